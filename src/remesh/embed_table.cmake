# cmake -DIN=table.txt -DOUT=file.cpp -P embed_table.cmake: the text as a C++ string constant.
file(READ "${IN}" content)
file(WRITE "${OUT}"
  "// Generated from ${IN} by embed_table.cmake; do not edit.\n"
  "#include <string_view>\n"
  "namespace qsmesh::remesh::detail {\n"
  "extern const std::string_view kDiskTableText;\n"
  "const std::string_view kDiskTableText = R\"qsmeshtable(${content})qsmeshtable\";\n"
  "}  // namespace qsmesh::remesh::detail\n")

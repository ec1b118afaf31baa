# cmake -DINPUT=data/patterns.txt -DOUTPUT=patterns_data.cpp -P QsmeshPatterns.cmake
# Turns the pattern file (format described at its top) into a C++ source with the raw data, so the
# library needs no data file at run time. Malformed lines stop the build with the line number.
if(NOT INPUT OR NOT OUTPUT)
  message(FATAL_ERROR "QsmeshPatterns.cmake: INPUT and OUTPUT must be set")
endif()
file(STRINGS "${INPUT}" lines)
set(number "[-+]?[0-9]*\\.?[0-9]+([eE][-+]?[0-9]+)?")
set(body "")
set(table "")
set(count 0)
set(inside FALSE)
set(lineno 0)
foreach(line IN LISTS lines)
  math(EXPR lineno "${lineno} + 1")
  string(STRIP "${line}" line)
  if(line STREQUAL "" OR line MATCHES "^#")
    continue()
  endif()
  if(line MATCHES "^pattern[ \t]+([A-Za-z0-9_]+)$")
    if(inside)
      message(FATAL_ERROR "${INPUT}:${lineno}: 'pattern' before the 'end' of ${name}")
    endif()
    set(name "${CMAKE_MATCH_1}")
    set(inside TRUE)
    set(xy "")
    set(quads "")
    set(nv 0)
    set(nq 0)
  elseif(NOT inside)
    message(FATAL_ERROR "${INPUT}:${lineno}: '${line}' outside a pattern block")
  elseif(line MATCHES "^v[ \t]+(${number})[ \t]+(${number})$")
    string(APPEND xy "${CMAKE_MATCH_1}, ${CMAKE_MATCH_3}, ")
    math(EXPR nv "${nv} + 1")
  elseif(line MATCHES "^q[ \t]+([0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)$")
    string(APPEND quads "${CMAKE_MATCH_1}, ${CMAKE_MATCH_2}, ${CMAKE_MATCH_3}, ${CMAKE_MATCH_4}, ")
    math(EXPR nq "${nq} + 1")
  elseif(line STREQUAL "end")
    if(nv EQUAL 0 OR nq EQUAL 0)
      message(FATAL_ERROR "${INPUT}:${lineno}: pattern ${name} has no vertex or no quad")
    endif()
    string(APPEND body "constexpr double kXY${count}[] = {${xy}};\n")
    string(APPEND body "constexpr LO kQuads${count}[] = {${quads}};\n")
    string(APPEND table "    {\"${name}\", kXY${count}, ${nv}, kQuads${count}, ${nq}},\n")
    math(EXPR count "${count} + 1")
    set(inside FALSE)
  else()
    message(FATAL_ERROR "${INPUT}:${lineno}: cannot read '${line}'")
  endif()
endforeach()
if(inside)
  message(FATAL_ERROR "${INPUT}: pattern ${name} has no 'end'")
endif()
if(count EQUAL 0)
  message(FATAL_ERROR "${INPUT}: no pattern")
endif()
set(text "// Generated at build time from data/patterns.txt by cmake/QsmeshPatterns.cmake. Do not edit.
#include \"pattern_data.hpp\"

namespace qsmesh::qstruct::detail {
namespace {
${body}
constexpr RawPattern kRaw[] = {
${table}};
}  // namespace

std::span<const RawPattern> raw_patterns() { return kRaw; }

}  // namespace qsmesh::qstruct::detail
")
# Rewritten only when it changes, so a touched but unchanged data file rebuilds nothing.
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
  if(old STREQUAL text)
    return()
  endif()
endif()
file(WRITE "${OUTPUT}" "${text}")

// write_mesh dispatch, path checks, atomic output, determinism.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

#include "io_test_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"
#include "qsmesh/io/writer.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::dir_entries;
using test::fresh_dir;
using test::make_test_mesh;
using test::read_all;

// Expects InputError whose message is one line naming `path`.
void expect_input_error(const std::function<void()>& f, const std::string& path) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(Writer, SupportedExtensionsAnyCase) {
  EXPECT_TRUE(is_supported_output("a.cgns"));
  EXPECT_TRUE(is_supported_output("dir/a.CGNS"));
  EXPECT_TRUE(is_supported_output("a.Vtu"));
  EXPECT_TRUE(is_supported_output("a.msh"));
  EXPECT_TRUE(is_supported_output("a.H5"));
  EXPECT_TRUE(is_supported_output("a.xyz"));
  EXPECT_TRUE(is_supported_output("a.P3D"));
  EXPECT_FALSE(is_supported_output("a.stl"));
  EXPECT_FALSE(is_supported_output("a"));
  EXPECT_FALSE(is_supported_output("a.msh.gz"));
  EXPECT_FALSE(is_supported_output(".msh"));
}

TEST(Writer, UnsupportedExtensionIsInputErrorBeforeAnyWork) {
  const fs::path dir = fresh_dir("unsupported");
  const std::string path = (dir / "out.stl").string();
  expect_input_error([&] { check_output_path(path); }, path);
  expect_input_error([&] { write_mesh(make_test_mesh(), path); }, path);
  // Checked before the mesh: an inconsistent mesh still gives the InputError.
  mesh::SurfaceMesh bad = make_test_mesh();
  bad.triangle_face.pop_back();
  expect_input_error([&] { write_mesh(bad, path); }, path);
  EXPECT_TRUE(dir_entries(dir).empty());
}

TEST(Writer, MissingOrUnwritableFolderIsInputError) {
  const fs::path dir = fresh_dir("nofolder");
  for (const char* ext : {".cgns", ".vtu", ".msh"}) {
    const std::string missing = (dir / "missing" / (std::string("out") + ext)).string();
    expect_input_error([&] { check_output_path(missing); }, missing);
    expect_input_error([&] { write_mesh(make_test_mesh(), missing); }, missing);
  }
  expect_input_error([&] { write_cgns(make_test_mesh(), (dir / "missing" / "x.cgns").string()); },
                     (dir / "missing" / "x.cgns").string());
  expect_input_error([&] { write_vtu(make_test_mesh(), (dir / "missing" / "x.vtu").string()); },
                     (dir / "missing" / "x.vtu").string());
  expect_input_error([&] { write_msh(make_test_mesh(), (dir / "missing" / "x.msh").string()); },
                     (dir / "missing" / "x.msh").string());
  // A regular file where the folder should be.
  std::ofstream(dir / "file") << "x";
  const std::string under_file = (dir / "file" / "out.msh").string();
  expect_input_error([&] { check_output_path(under_file); }, under_file);
  // The output names a folder.
  fs::create_directory(dir / "sub.vtu");
  const std::string folder = (dir / "sub.vtu").string();
  expect_input_error([&] { check_output_path(folder); }, folder);
  // Permission bits do not stop root; only check them when not root.
  if (::geteuid() != 0) {
    fs::create_directory(dir / "ro");
    fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    const std::string ro = (dir / "ro" / "out.cgns").string();
    expect_input_error([&] { check_output_path(ro); }, ro);
    fs::permissions(dir / "ro", fs::perms::owner_all);
  }
  EXPECT_NO_THROW(check_output_path((dir / "ok.MSH").string()));
}

TEST(Writer, InconsistentMeshIsError) {
  const fs::path dir = fresh_dir("inconsistent");
  mesh::SurfaceMesh m = make_test_mesh();
  m.quads[1][2] = 99;
  EXPECT_THROW(check_mesh_for_output(m), Error);
  for (const char* name : {"a.cgns", "a.vtu", "a.msh"}) {
    EXPECT_THROW(write_mesh(m, (dir / name).string()), Error) << name;
  }
  m = make_test_mesh();
  m.bar_curve[0] = 10;
  EXPECT_THROW(check_mesh_for_output(m), Error);
  m = make_test_mesh();
  m.vclass.pop_back();
  EXPECT_THROW(check_mesh_for_output(m), Error);
  EXPECT_TRUE(dir_entries(dir).empty());
  EXPECT_NO_THROW(check_mesh_for_output(make_test_mesh()));
}

TEST(AtomicFile, CommitRenamesAndFailureLeavesNothing) {
  const fs::path dir = fresh_dir("atomic");
  const std::string path = (dir / "out.txt").string();
  {
    AtomicFile a(path);
    EXPECT_EQ(fs::path(a.temp_path()).parent_path(), dir);
    EXPECT_EQ(fs::path(a.temp_path()).filename().string().rfind(".out.txt.tmp.", 0), 0u);
    OutputFile f(a.temp_path());
    f << "hello " << 42 << ' ' << 0.1 << '\n';
    f.close();
    EXPECT_TRUE(fs::exists(a.temp_path()));
    EXPECT_FALSE(fs::exists(path));
    a.commit();
    EXPECT_TRUE(a.committed());
  }
  EXPECT_EQ(read_all(path), "hello 42 0.1\n");
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"out.txt"});

  // A failure midway: the temporary is gone, the existing file is untouched.
  try {
    AtomicFile a(path);
    OutputFile f(a.temp_path());
    f << "partial";
    f.close();
    throw std::runtime_error("injected");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read_all(path), "hello 42 0.1\n");
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"out.txt"});

  // And with no previous file, nothing is left at all.
  const std::string fresh = (dir / "fresh.txt").string();
  try {
    AtomicFile a(fresh);
    OutputFile f(a.temp_path());
    f << "partial";
    throw std::runtime_error("injected");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, WriterFailingMidwayLeavesNothing) {
  const fs::path dir = fresh_dir("midway");
  // cgnslib refuses names longer than 32 characters: cg_base_write fails after cg_open created
  // the temporary file.
  WriteOptions opt;
  opt.cgns_base_name = std::string(40, 'b');
  const std::string path = (dir / "m.cgns").string();
  try {
    write_mesh(make_test_mesh(), path, opt);
    ADD_FAILURE() << "no error for a 40-character base name";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cg_base_write"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(dir_entries(dir).empty());

  // The same over an existing file: it survives unchanged.
  std::ofstream(path) << "old";
  EXPECT_THROW(write_mesh(make_test_mesh(), path, opt), Error);
  EXPECT_EQ(read_all(path), "old");
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.cgns"});

  // An unknown length unit is refused before the file is created.
  mesh::SurfaceMesh m = make_test_mesh();
  m.length_unit = "furlong";
  EXPECT_THROW(write_cgns(m, (dir / "u.cgns").string()), Error);
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.cgns"});
}

TEST(Writer, SameMeshGivesIdenticalBytes) {
  const fs::path dir = fresh_dir("determinism");
  for (const char* ext : {".cgns", ".vtu", ".msh", ".h5", ".xyz"}) {
    const std::string a = (dir / (std::string("a") + ext)).string();
    const std::string b = (dir / (std::string("b") + ext)).string();
    write_mesh(make_test_mesh(), a);
    write_mesh(make_test_mesh(), b);
    const std::string ca = read_all(a);
    EXPECT_GT(ca.size(), 100u) << ext;
    EXPECT_TRUE(ca == read_all(b)) << ext << " differs between two writes";
    // Rewriting over an existing file replaces it.
    write_mesh(make_test_mesh(), a);
    EXPECT_TRUE(ca == read_all(a)) << ext;
  }
  // No temporaries left (.h5 comes with .xdmf, .xyz with .xyz.json).
  EXPECT_EQ(dir_entries(dir).size(), 14u);
}

TEST(Writer, UpperCaseExtensionDispatches) {
  const fs::path dir = fresh_dir("upper");
  write_mesh(make_test_mesh(), (dir / "a.MSH").string());
  write_mesh(make_test_mesh(), (dir / "a.Vtu").string());
  EXPECT_EQ(read_all(dir / "a.MSH").rfind("$MeshFormat\n4.1 0 8\n", 0), 0u);
  EXPECT_EQ(read_all(dir / "a.Vtu").rfind("<?xml", 0), 0u);
}

}  // namespace
}  // namespace qsmesh::io

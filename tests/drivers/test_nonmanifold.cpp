// The qsmesh executable on STEP models with curves that three faces border: a T of three plates,
// and a box whose top face the file gives twice. Every output is written, the mesh conforms, and
// the block-structured file passes the block reader, at two size factors.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "cgns_blocks_check.hpp"
#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace {

using qsmesh::test::slurp;
using qsmesh::test::tmp;

// Exit code of `qsmesh ARGS` (output to files beside the test's).
int qsmesh(const std::string& args, const std::string& log) {
  const std::string cmd = std::string(QSMESH_EXE) + " " + args + " >" + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Every output of `mesh` on `model` at two size factors: conforming (--stats), written, and a
// block file that passes the reader.
void check_outputs(const std::string& model, const std::string& name, int non_manifold) {
  // The STEP file holds the shared edges: that many curves border three faces or more.
  const qsmesh::cad::CadModel cad = qsmesh::cad::load_cad(model);
  int n = 0;
  for (qsmesh::LO c = 0; c < cad.num_curves(); ++c) n += cad.curve2faces()[c].size() >= 3 ? 1 : 0;
  ASSERT_EQ(n, non_manifold);
  for (const char* factor : {"0.1", "0.03"}) {
    const std::string stem = tmp(name + "_" + factor);
    const std::string stats = stem + ".json";
    ASSERT_EQ(qsmesh("mesh " + model + " -o " + stem + ".msh --size-factor " + factor +
                         " -q --stats " + stats,
                     stem + ".log"),
              0)
        << slurp(stem + ".log");
    const std::string json = slurp(stats);
    EXPECT_NE(json.find("\"conforming\": true"), std::string::npos) << name << " " << factor;
    for (const char* ext : {".cgns", ".vtu", ".h5"})
      EXPECT_EQ(qsmesh("mesh " + model + " -o " + stem + ext + " --size-factor " + factor + " -q",
                       stem + ".log"),
                0)
          << ext << ": " << slurp(stem + ".log");
    const std::string blocks = stem + "_blocks.cgns";
    ASSERT_EQ(qsmesh("mesh " + model + " -o " + blocks + " --block-structured --size-factor " +
                         factor + " -q",
                     stem + ".log"),
              0)
        << slurp(stem + ".log");
    const qsmesh::test::BlockFileSummary s = qsmesh::test::check_block_file(blocks);
    EXPECT_EQ(s.error.substr(0, 1000), "") << name << " at size factor " << factor;
    EXPECT_EQ(s.unstructured_zones, 0);
    EXPECT_GT(s.interfaces, 0);
  }
}

TEST(NonManifoldExe, TOfThreePlatesFromStep) {
  const std::string model = tmp("nm_t.step");
  qsmesh::test::write_t_of_three_plates(model);
  check_outputs(model, "nm_t", 1);
}

TEST(NonManifoldExe, BoxWithItsTopGivenTwiceFromStep) {
  const std::string model = tmp("nm_box.step");
  qsmesh::test::write_box_with_duplicated_face(6.0, model);
  check_outputs(model, "nm_box", 4);
}

}  // namespace

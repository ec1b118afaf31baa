// What a killed run leaves beside its outputs: hidden temporaries and set-aside earlier files,
// named after the output and the process (atomic_file.hpp), found and cleaned by a later run.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io_test_mesh.hpp"
#include "qsmesh/io/atomic_file.hpp"

namespace qsmesh::io {
namespace {

namespace fs = std::filesystem;
using test::dir_entries;
using test::fresh_dir;
using test::read_all;

void touch(const fs::path& p, const std::string& text = "x") { std::ofstream(p) << text; }

// A process id that certainly names no process now: a child that has exited and been reaped.
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return static_cast<long>(child);
}

TEST(Leftovers, NamesFollowTheAtomicFile) {
  const fs::path dir = fresh_dir("leftover_names");
  const std::string out = (dir / "m.msh").string();
  EXPECT_EQ(temporary_path(out, 42), (dir / ".m.msh.tmp.42").string());
  EXPECT_EQ(aside_path(out, 42), (dir / ".m.msh.old.42").string());
  AtomicFile a(out);
  EXPECT_EQ(a.temp_path(), temporary_path(out, ::getpid()));
}

TEST(Leftovers, ListsOnlyThisOutputsFilesOfDeadProcesses) {
  const fs::path dir = fresh_dir("leftover_list");
  const std::string out = (dir / "m.msh").string();
  for (const char* name :
       {"m.msh", ".m.msh.tmp.111", ".m.msh.old.111", ".m.msh.tmp.222", ".m.msh.tmp.12x",
        ".m.msh.tmp.", ".m.msh.tmp.-5", ".m.msh.tmp.+5", ".m.msh.new.111", ".other.msh.tmp.111",
        ".m.msh.tmp.111.x", "m.msh.tmp.111", ".m.ms.tmp.111", ".m.msh.vtu.tmp.111"})
    touch(dir / name);
  std::vector<long> asked;
  const auto alive = [&](long pid) {
    asked.push_back(pid);
    return pid == 222;
  };
  const std::vector<LeftoverFile> found = find_leftovers(out, alive);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].path, (dir / ".m.msh.old.111").string());
  EXPECT_EQ(found[0].pid, 111);
  EXPECT_TRUE(found[0].aside);
  EXPECT_EQ(found[1].path, (dir / ".m.msh.tmp.111").string());
  EXPECT_EQ(found[1].pid, 111);
  EXPECT_FALSE(found[1].aside);
  std::sort(asked.begin(), asked.end());
  EXPECT_EQ(asked, (std::vector<long>{111, 111, 222}));  // only well-formed names are asked about
  EXPECT_EQ(dir_entries(dir).size(), 14u);               // listing touches nothing

  // A missing folder has nothing to list.
  EXPECT_TRUE(find_leftovers((dir / "absent" / "m.msh").string(), alive).empty());
}

TEST(Leftovers, CleanRemovesTemporariesAndSetAsideCopies) {
  const fs::path dir = fresh_dir("leftover_clean");
  const std::string out = (dir / "m.h5").string();
  touch(out, "newer");
  touch(dir / ".m.h5.tmp.111");
  touch(dir / ".m.h5.old.111", "older");
  touch(dir / ".m.h5.tmp.222");
  touch(dir / ".m.xdmf.tmp.111");
  const std::vector<std::string> lines =
      clean_leftovers(out, find_leftovers(out, [](long pid) { return pid == 222; }));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[1].find("removed stale temporary " + (dir / ".m.h5.tmp.111").string() +
                          " of an interrupted run (process 111)"),
            std::string::npos)
      << lines[1];
  EXPECT_NE(lines[0].find((dir / ".m.h5.old.111").string()), std::string::npos) << lines[0];
  EXPECT_EQ(dir_entries(dir),
            (std::vector<std::string>{".m.h5.tmp.222", ".m.xdmf.tmp.111", "m.h5"}));
  EXPECT_EQ(read_all(out), "newer");
}

TEST(Leftovers, SetAsideCopyIsPutBackWhenTheOutputIsMissing) {
  // Killed after commit_together moved the earlier file aside, before the new one was renamed in.
  const fs::path dir = fresh_dir("leftover_restore");
  const std::string out = (dir / "m.h5").string();
  touch(dir / ".m.h5.old.111", "earlier");
  touch(dir / ".m.h5.tmp.111", "partial");
  const std::vector<std::string> lines =
      clean_leftovers(out, find_leftovers(out, [](long) { return false; }));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0].find("put back " + out), std::string::npos) << lines[0];
  EXPECT_EQ(dir_entries(dir), std::vector<std::string>{"m.h5"});
  EXPECT_EQ(read_all(out), "earlier");
}

TEST(Leftovers, LiveProcessesKeepTheirTemporaries) {
  const fs::path dir = fresh_dir("leftover_live");
  const std::string out = (dir / "m.vtu").string();
  const long dead = dead_pid();
  EXPECT_TRUE(process_exists(::getpid()));
  EXPECT_TRUE(process_exists(1));  // another user's process (or ours): alive either way
  EXPECT_FALSE(process_exists(dead));
  touch(temporary_path(out, ::getpid()));
  touch(temporary_path(out, dead));
  const std::vector<LeftoverFile> found = find_leftovers(out, process_exists);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].path, temporary_path(out, dead));
  EXPECT_EQ(found[0].pid, dead);
  (void)clean_leftovers(out, found);
  EXPECT_EQ(dir_entries(dir),
            std::vector<std::string>{fs::path(temporary_path(out, ::getpid())).filename()});
}

}  // namespace
}  // namespace qsmesh::io

// The qsmesh executable interrupted by a signal: it removes its temporaries and dies of the signal;
// a later run removes what a killed one (SIGKILL) left. Also: no arguments is a usage error.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "shapes.hpp"
#include "tmp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

using qsmesh::test::slurp;

// A folder of its own for each test (ctest runs several test processes at once).
fs::path fresh_dir(const std::string& name) {
  // Appended rather than "p" + ...: GCC 12 reports a false -Wrestrict on that concatenation.
  std::string folder = "p";
  folder += std::to_string(::getpid());
  folder += '_';
  folder += name;
  const fs::path dir = fs::path(QSMESH_TEST_TMP_DIR) / folder;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> hidden_files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (!n.empty() && n[0] == '.') names.push_back(n);
  }
  std::sort(names.begin(), names.end());
  return names;
}

void touch(const fs::path& p, const std::string& text = "x") { std::ofstream(p) << text; }

struct Child {
  pid_t pid = -1;
  int err = -1;  ///< read end of its stderr when piped, else -1
};

// Starts qsmesh with `args`: stdout to /dev/null, stderr to a pipe (which the caller reads or
// not: a full pipe stops the run) or to `err_file`. The termination signals are reset to their
// defaults and unblocked, as a shell would start it in the foreground. `nice_level` lowers its
// priority.
Child start(const std::vector<std::string>& args, const std::string& err_file = {},
            int nice_level = 0) {
  std::vector<std::string> all{QSMESH_EXE};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  int fds[2] = {-1, -1};
  if (err_file.empty()) {
    if (::pipe2(fds, O_CLOEXEC) != 0) return {};
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Only async-signal-safe calls between fork and exec.
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    const int e =
        err_file.empty() ? fds[1] : ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(e, 2);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &dfl, nullptr);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    if (nice_level != 0) (void)::nice(nice_level);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (err_file.empty()) ::close(fds[1]);
  return {pid, fds[0]};
}

// waitpid with a deadline; kills the child (and reports -1) when it is not done by then.
int wait_for(pid_t pid, double seconds) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return status;
}

// Reads `fd` up to and including the first newline (false at end of file).
bool read_line(int fd, std::string& line) {
  line.clear();
  char c = 0;
  while (::read(fd, &c, 1) == 1) {
    line.push_back(c);
    if (c == '\n') return true;
  }
  return false;
}

std::string describe(int status) {
  if (status == -1) return "still running after the deadline (killed)";
  if (WIFEXITED(status)) return "exited with " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by ") + ::strsignal(WTERMSIG(status));
  return "status " + std::to_string(status);
}

class Signals : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path dir = fresh_dir("signal_models");
    model_ = (dir / "fillet.step").string();
    qsmesh::test::write_filleted_box(model_);
  }
  static std::string model_;
};
std::string Signals::model_;

class SignalDuringRun : public Signals, public ::testing::WithParamInterface<int> {};

// Deterministic: the child is stopped (SIGSTOP) once it has logged its first line, so the signal
// provably arrives during the run, after the handler was installed. The files its writers would
// have at that moment are made here under its pid: the handler must remove them, put the
// set-aside earlier .h5 back, leave other processes' files, and the process must die of the
// signal (a shell then reports 128 + signal).
TEST_P(SignalDuringRun, InterruptedRunRemovesItsTemporariesAndDiesOfTheSignal) {
  const int sig = GetParam();
  const fs::path dir = fresh_dir(std::string("signal_run_") + std::to_string(sig));
  const fs::path out = dir / "out.h5";
  const Child child = start({"mesh", model_, "-o", out.string(), "--stats",
                             (dir / "out.json").string(), "--size", "0.5", "--threads", "2"});
  ASSERT_GT(child.pid, 0);
  std::string line;
  ASSERT_TRUE(read_line(child.err, line)) << "no line on stderr";
  ASSERT_EQ(::kill(child.pid, SIGSTOP), 0);
  int stopped = 0;
  ASSERT_EQ(::waitpid(child.pid, &stopped, WUNTRACED), child.pid);
  ASSERT_TRUE(WIFSTOPPED(stopped)) << "the run ended before the signal: " << describe(stopped);
  const std::string pid = std::to_string(child.pid);
  const std::string other = std::to_string(::getpid());  // alive: a concurrent run's files
  for (const std::string& name : {".out.h5.tmp." + pid, ".out.xdmf.tmp." + pid,
                                  ".out.json.tmp." + pid, ".out.h5.tmp." + other})
    touch(dir / name, "partial");
  touch(dir / (".out.h5.old." + pid), "earlier");
  ASSERT_EQ(::kill(child.pid, sig), 0);  // pending until the process runs again
  ASSERT_EQ(::kill(child.pid, SIGCONT), 0);
  const int status = wait_for(child.pid, 60);
  ::close(child.err);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << describe(status);
  EXPECT_EQ(hidden_files(dir), std::vector<std::string>{".out.h5.tmp." + other});
  EXPECT_EQ(slurp(out.string()), "earlier");
  EXPECT_FALSE(fs::exists(dir / "out.json"));
  EXPECT_FALSE(fs::exists(dir / "out.xdmf"));
}

INSTANTIATE_TEST_SUITE_P(Termination, SignalDuringRun, ::testing::Values(SIGTERM, SIGINT, SIGHUP),
                         [](const ::testing::TestParamInfo<int>& p) {
                           return std::string(p.param == SIGTERM  ? "SIGTERM"
                                              : p.param == SIGINT ? "SIGINT"
                                                                  : "SIGHUP");
                         });

// The same with the real writer: the signal is sent as soon as the temporary of the mesh appears
// (inotify), while the child, at the lowest priority, is writing it. If the write still wins (the
// run exits 0), that try proves nothing and is repeated.
TEST_F(Signals, TermDuringTheMeshWriteLeavesNoTemporary) {
  const fs::path dir = fresh_dir("signal_write");
  const fs::path out = dir / "out.msh";
  const int tries = 3;
  for (int attempt = 0; attempt < tries; ++attempt) {
    const int watch = ::inotify_init1(IN_CLOEXEC);
    ASSERT_GE(watch, 0) << std::strerror(errno);
    ASSERT_GE(::inotify_add_watch(watch, dir.c_str(), IN_CREATE), 0) << std::strerror(errno);
    const std::string err = (dir.parent_path() / (dir.filename().string() + "_err")).string();
    const Child child = start({"mesh", model_, "-o", out.string(), "--size", "0.25", "--threads",
                               "1", "--until", "background", "-q"},
                              err, 19);
    ASSERT_GT(child.pid, 0);
    const std::string temp = ".out.msh.tmp." + std::to_string(child.pid);
    bool signalled = false;
    bool ended = false;
    alignas(inotify_event) char buf[4096];
    while (!signalled && !ended) {
      pollfd p{watch, POLLIN, 0};
      if (::poll(&p, 1, 100) == 1) {
        const ssize_t n = ::read(watch, buf, sizeof buf);
        ASSERT_GT(n, 0) << std::strerror(errno);
        for (ssize_t at = 0; at < n && !signalled;) {
          const auto* ev = reinterpret_cast<const inotify_event*>(buf + at);
          if (ev->len > 0 && temp == ev->name) signalled = ::kill(child.pid, SIGTERM) == 0;
          at += static_cast<ssize_t>(sizeof(inotify_event) + ev->len);
        }
      } else {
        ended = ::waitpid(child.pid, nullptr, WNOHANG) != 0;  // failed before writing
      }
    }
    ::close(watch);
    ASSERT_FALSE(ended) << "the run ended without writing " << temp << ": " << slurp(err);
    const int status = wait_for(child.pid, 60);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
      std::cout << "try " << attempt + 1 << ": the write finished before the signal\n";
      fs::remove(out);
      continue;
    }
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM)
        << describe(status) << slurp(err);
    EXPECT_EQ(hidden_files(dir), std::vector<std::string>{});
    EXPECT_FALSE(fs::exists(out));
    return;
  }
  GTEST_SKIP() << "the mesh write finished before the signal in " << tries << " tries";
}

// A process id that names no process: a child that has exited and been reaped.
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return static_cast<long>(child);
}

// SIGKILL leaves the temporaries (no handler runs): the next run writing the same outputs removes
// those of processes that no longer exist, saying so, and leaves those of live ones.
TEST_F(Signals, NextRunRemovesTemporariesOfKilledRuns) {
  const fs::path dir = fresh_dir("signal_stale");
  const std::string dead = std::to_string(dead_pid());
  const std::string live = std::to_string(::getpid());
  const std::vector<std::string> stale{".out.h5.tmp." + dead, ".out.xdmf.tmp." + dead,
                                       ".out.json.tmp." + dead};
  for (const std::string& name : stale) touch(dir / name, std::string(3u << 20, 'x'));
  touch(dir / (".out.h5.tmp." + live));
  touch(dir / (".other.h5.tmp." + dead));
  const std::string err = (dir / "err.txt").string();
  const Child child = start({"mesh", model_, "-o", (dir / "out.h5").string(), "--stats",
                             (dir / "out.json").string(), "--size", "1.5", "--until", "background"},
                            err);
  const int status = wait_for(child.pid, 60);
  const std::string log = slurp(err);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << describe(status) << log;
  for (const std::string& name : stale)
    EXPECT_NE(log.find("removed stale temporary " + (dir / name).string() +
                       " of an interrupted run (process " + dead + ")"),
              std::string::npos)
        << log;
  EXPECT_EQ(hidden_files(dir),
            (std::vector<std::string>{".other.h5.tmp." + dead, ".out.h5.tmp." + live}));
  EXPECT_TRUE(fs::exists(dir / "out.h5"));
  EXPECT_TRUE(fs::exists(dir / "out.xdmf"));
  EXPECT_TRUE(fs::exists(dir / "out.json"));
}

// `qsmesh` alone asks for nothing: the general help on stderr and the usage-error code.
TEST(QsmeshNoArguments, PrintsHelpAndExits2) {
  const fs::path dir = fresh_dir("no_arguments");
  const std::string err = (dir / "err.txt").string();
  const Child child = start({}, err);
  const int status = wait_for(child.pid, 30);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << describe(status);
  EXPECT_NE(slurp(err).find("usage"), std::string::npos) << slurp(err);
}

}  // namespace

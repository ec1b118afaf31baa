// Removing a run's temporary files when it is interrupted by a signal.
#pragma once

#include <pthread.h>
#include <signal.h>

#include <array>
#include <string>
#include <vector>

namespace qsmesh::io {

/// While alive, SIGINT, SIGTERM and SIGHUP make this process remove its own temporaries of
/// `outputs` (temporary_path(output, getpid()), atomic_file.hpp), put back an earlier output that
/// commit_together had moved aside (aside_path) when the output itself is missing, and then die of
/// that same signal: the default action is restored and the signal raised again, so that a shell
/// reports $? = 128 + signal, a parent's waitpid sees WIFSIGNALED (a calling shell script stops on
/// SIGINT, as it should), and mpirun (Open MPI 4.1), when a rank is signalled directly (a batch
/// scheduler), reports "exited on signal N" and exits 128 + N itself. mpirun signalled itself
/// sends the ranks SIGCONT, SIGTERM one second later, SIGKILL one more second later, and exits 1.
/// A signal that was ignored when the object was made (nohup, a background job of a script) stays
/// ignored. The destructor puts the earlier actions back.
///
/// Why there is process-wide state: a signal handler receives no context, so the active object
/// publishes one pointer to its table of file names, precomputed C strings, which the handler only
/// reads. The handler calls only async-signal-safe functions (unlink, access, rename, sigaction,
/// pthread_sigmask, pthread_kill, raise, _exit); nothing is allocated or filled on first use.
/// Hence at most one SignalCleanup may exist at a time (a second one throws qsmesh::Error).
///
/// The object must be made by the thread that writes the outputs (the driver's main thread): a
/// signal the kernel hands to another thread (a TBB worker, an MPI progress thread) is passed on to
/// it, so that no file is created or renamed while the handler cleans up.
class SignalCleanup {
 public:
  /// `outputs`: every file this process may write (empty names are skipped). Installs the handler.
  explicit SignalCleanup(const std::vector<std::string>& outputs);
  ~SignalCleanup();
  SignalCleanup(const SignalCleanup&) = delete;
  SignalCleanup& operator=(const SignalCleanup&) = delete;

  /// The signals handled.
  static constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};

  /// What the handler reads: plain arrays of C strings, fixed before the handler is installed.
  struct Table {
    const char* const* temporaries = nullptr;  ///< removed
    const char* const* asides = nullptr;       ///< asides[i] is put back as finals[i] if missing
    const char* const* finals = nullptr;
    std::size_t num_temporaries = 0;
    std::size_t num_asides = 0;
    pthread_t owner{};  ///< the thread that handles the signal
  };

 private:
  void install();
  void uninstall();
  std::vector<std::string> temporaries_, asides_, finals_;
  std::vector<const char*> temporary_ptrs_, aside_ptrs_, final_ptrs_;
  Table table_;
  std::array<struct sigaction, kSignals.size()> previous_{};
  std::array<bool, kSignals.size()> installed_{};
};

}  // namespace qsmesh::io

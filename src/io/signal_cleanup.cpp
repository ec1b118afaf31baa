#include "qsmesh/io/signal_cleanup.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>

#include "qsmesh/core/error.hpp"
#include "qsmesh/io/atomic_file.hpp"

namespace qsmesh::io {

namespace {

// The one piece of process-wide state (see the header): the table of the SignalCleanup alive, or
// null. Set by its constructor, cleared by its destructor; the handler only loads it.
std::atomic<const SignalCleanup::Table*> g_active_table{nullptr};
static_assert(std::atomic<const SignalCleanup::Table*>::is_always_lock_free,
              "the signal handler needs a lock-free pointer");

[[noreturn]] void die_of(int sig) {
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  ::sigaction(sig, &dfl, nullptr);
  // The signal is blocked while its handler runs: unblock it so that raise() delivers it now.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, sig);
  ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
  ::raise(sig);
  ::_exit(128 + sig);  // only if the default action did not end the process
}

extern "C" void on_termination_signal(int sig) {
  const int saved_errno = errno;
  const SignalCleanup::Table* t = g_active_table.load();
  if (t == nullptr) die_of(sig);
  if (::pthread_equal(::pthread_self(), t->owner) == 0) {
    // Another thread got it: the writing thread cleans up, so that it cannot create or rename a
    // file between the cleanup and the end of the process.
    ::pthread_kill(t->owner, sig);
    errno = saved_errno;
    return;
  }
  for (std::size_t i = 0; i < t->num_temporaries; ++i) ::unlink(t->temporaries[i]);
  for (std::size_t i = 0; i < t->num_asides; ++i) {
    if (::access(t->finals[i], F_OK) != 0 && errno == ENOENT) ::rename(t->asides[i], t->finals[i]);
  }
  die_of(sig);
}

}  // namespace

SignalCleanup::SignalCleanup(const std::vector<std::string>& outputs) {
  const long pid = static_cast<long>(::getpid());
  for (const std::string& out : outputs) {
    if (out.empty()) continue;
    temporaries_.push_back(temporary_path(out, pid));
    asides_.push_back(aside_path(out, pid));
    finals_.push_back(out);
  }
  // The strings no longer change: their C strings stay valid as long as the object.
  for (const std::string& s : temporaries_) temporary_ptrs_.push_back(s.c_str());
  for (const std::string& s : asides_) aside_ptrs_.push_back(s.c_str());
  for (const std::string& s : finals_) final_ptrs_.push_back(s.c_str());
  table_.temporaries = temporary_ptrs_.data();
  table_.asides = aside_ptrs_.data();
  table_.finals = final_ptrs_.data();
  table_.num_temporaries = temporary_ptrs_.size();
  table_.num_asides = aside_ptrs_.size();
  table_.owner = ::pthread_self();

  const Table* expected = nullptr;
  QSMESH_CHECK(g_active_table.compare_exchange_strong(expected, &table_),
               "SignalCleanup: another one is already installed");
  try {
    install();
  } catch (...) {
    uninstall();
    throw;
  }
}

void SignalCleanup::install() {
  struct sigaction action {};
  action.sa_handler = on_termination_signal;
  // A thread that passes the signal on resumes its system call instead of failing with EINTR.
  action.sa_flags = SA_RESTART;
  sigemptyset(&action.sa_mask);
  // One cleanup at a time: the other signals wait while the handler runs (and then find the
  // process gone).
  for (int sig : kSignals) sigaddset(&action.sa_mask, sig);
  sigset_t unblock;
  sigemptyset(&unblock);
  for (std::size_t i = 0; i < kSignals.size(); ++i) {
    const int sig = kSignals[i];
    QSMESH_CHECK(::sigaction(sig, nullptr, &previous_[i]) == 0,
                 "SignalCleanup: cannot read the action of signal " << sig);
    // Ignored on entry (nohup, a background job of a script): the caller meant it to be.
    if (previous_[i].sa_handler == SIG_IGN) continue;
    QSMESH_CHECK(::sigaction(sig, &action, nullptr) == 0,
                 "SignalCleanup: cannot install the handler of signal " << sig);
    installed_[i] = true;
    sigaddset(&unblock, sig);
  }
  // Blocked here, a signal would go to another thread and be passed back to this one forever.
  QSMESH_CHECK(::pthread_sigmask(SIG_UNBLOCK, &unblock, nullptr) == 0,
               "SignalCleanup: cannot unblock the termination signals");
}

void SignalCleanup::uninstall() {
  // Actions first: a signal arriving in between then takes the earlier action, never a handler
  // without its table.
  for (std::size_t i = 0; i < kSignals.size(); ++i)
    if (installed_[i]) ::sigaction(kSignals[i], &previous_[i], nullptr);
  installed_ = {};
  g_active_table.store(nullptr);
}

SignalCleanup::~SignalCleanup() { uninstall(); }

}  // namespace qsmesh::io

#include "output/interrupt.h"

#include <semaphore.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <mutex>
#include <thread>

namespace pmr {
namespace {

constexpr timespec kDeadline = {1, 500000000};  // from the first signal to the exit
constexpr int kSlots = 64;
constexpr size_t kPathMax = 4096;
char g_paths[kSlots][kPathMax];
std::atomic<int> g_slot_state[kSlots];  // 0 free, 1 being filled, 2 live
std::atomic<int> g_signal{0};
sem_t g_deadline;                 // posted by the first signal: the watchdog's count-down starts
std::atomic<int> g_lock_fd{-1};   // the run's folder lock (register_lock_file), -1 when none
char g_lock_path[kPathMax];

void release_lock() {
  const int fd = g_lock_fd.exchange(-1);
  if (fd >= 0) remove_lock_if_last(fd, g_lock_path);
}

// The second signal's exit (and the watchdog's): async-signal-safe calls only.
[[noreturn]] void stop_now(const char* msg, size_t length) {
  for (int i = 0; i < kSlots; ++i)
    if (g_slot_state[i].load() == 2) ::unlink(g_paths[i]);
  release_lock();
  (void)!::write(2, msg, length);
  ::_exit(128 + g_signal.load());
}

void on_signal(int sig) {
  int expected = 0;
  if (g_signal.compare_exchange_strong(expected, sig)) {
    const char msg[] =
        "\npmr: interrupted: finishing cleanly (the frame in flight is dropped; signal again to stop at once)\n";
    (void)!::write(2, msg, sizeof msg - 1);
    ::sem_post(&g_deadline);
    return;
  }
  const char msg[] = "pmr: stopped at once; temporary files removed\n";
  stop_now(msg, sizeof msg - 1);
}

// A kernel launch or a long frame does not look at the flag: the first signal ends the run within
// kDeadline whatever is running, as a second signal would (a scheduler's grace period is short).
void watchdog() {
  while (::sem_wait(&g_deadline) != 0) {
  }
  timespec left = kDeadline;
  while (::nanosleep(&left, &left) != 0) {
  }
  const char msg[] = "pmr: stopped 1.5 s after the signal (the work in flight did not end); temporary files removed\n";
  stop_now(msg, sizeof msg - 1);
}

}  // namespace

void install_interrupt_handlers() {
  static std::once_flag started;
  std::call_once(started, [] {
    ::sem_init(&g_deadline, 0, 0);
    std::thread(watchdog).detach();
  });
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sa.sa_flags = SA_RESTART;  // other threads' blocking writes go on instead of failing with EINTR
  sigemptyset(&sa.sa_mask);
  // what schedulers send before a kill: SGE's -notify (USR1, USR2), Slurm's --signal, a CPU-time limit (XCPU)
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGALRM, SIGXCPU, SIGUSR1, SIGUSR2}) sigaction(sig, &sa, nullptr);
}

void remove_lock_if_last(int fd, const char* path) {
  struct stat held {}, named {};
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0 && ::fstat(fd, &held) == 0 && ::stat(path, &named) == 0 &&
      held.st_dev == named.st_dev && held.st_ino == named.st_ino)
    ::unlink(path);
}

void register_lock_file(int fd, const std::string& path) {
  if (path.size() >= kPathMax) return;  // then only the run's own exit releases it
  std::memcpy(g_lock_path, path.c_str(), path.size() + 1);
  g_lock_fd.store(fd);
}

void unregister_lock_file() { g_lock_fd.store(-1); }

void ignore_write_signals() {
  ::signal(SIGPIPE, SIG_IGN);
  ::signal(SIGXFSZ, SIG_IGN);
}

int interrupt_signal() { return g_signal.load(); }

const char* interrupt_signal_name(int sig) {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGALRM:
      return "SIGALRM";
    case SIGXCPU:
      return "SIGXCPU";
    case SIGUSR1:
      return "SIGUSR1";
    case SIGUSR2:
      return "SIGUSR2";
    default:
      return "a signal";
  }
}

int register_temp_file(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_slot_state[i].compare_exchange_strong(expected, 1)) {
      std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
      g_slot_state[i].store(2);
      return i;
    }
  }
  return -1;
}

void unregister_temp_file(int slot) {
  if (slot >= 0 && slot < kSlots) g_slot_state[slot].store(0);
}

}  // namespace pmr

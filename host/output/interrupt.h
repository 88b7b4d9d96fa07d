// Clean interruption of long jobs (SIGINT, SIGTERM, SIGHUP: a closed terminal or SSH session, SIGALRM). The first signal sets a flag that the frame loop
// and the writer poll: the frame in flight is abandoned, finished files stay. A second signal, or 1.5 s
// after the first when the run has not ended by then (a long frame's kernels do not poll), exits at
// once, after unlinking every temporary file still open (AtomicFile registers them here) and releasing
// the folder's lock (FolderGuard registers it), so no partial file and no stale lock is left either
// way. Everything the handler and the watchdog touch is async-signal-safe: fixed slots, atomics,
// sem_post, flock, stat, unlink, write and _exit.
#pragma once
#include <string>

namespace pmr {

// Installs the handlers (idempotent). Call once before a long job starts.
void install_interrupt_handlers();
// A closed pipe (`pmr render ... 2>&1 | head`) and a file-size limit (SIGPIPE, SIGXFSZ) fail the write
// instead of killing the process: messages to a closed pipe are lost, and a file that cannot be written
// is reported by its writer (one error, no partial file, no stale lock). Called first by main().
void ignore_write_signals();
// 0 while running, else the first signal received (SIGINT, SIGTERM, SIGHUP or SIGALRM); a job stopped by
// one exits 128 + it.
int interrupt_signal();
// "SIGINT", "SIGTERM", "SIGHUP", "SIGALRM".
const char* interrupt_signal_name(int sig);

// Temporary files open right now (AtomicFile). register returns a slot (-1 when all are busy: the file is
// then only cleaned up by its destructor).
int register_temp_file(const std::string& path);
void unregister_temp_file(int slot);

// Removes the lock file `path` that `fd` holds when no other process holds it (an exclusive flock
// succeeds) and the name is still that file. Async-signal-safe: FolderGuard::release and the exit by
// signal both call it.
void remove_lock_if_last(int fd, const char* path);
// The run's folder lock (one per process): an exit by signal releases it with remove_lock_if_last.
void register_lock_file(int fd, const std::string& path);
void unregister_lock_file();

}  // namespace pmr

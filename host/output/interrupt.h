// Clean interruption of long jobs (SIGINT, SIGTERM). The first signal sets a flag that the frame loop
// and the writer poll: the frame in flight is abandoned, finished files stay. A second signal exits at
// once, after unlinking every temporary file still open (AtomicFile registers them here), so no partial
// file is left either way. Everything the handler touches is async-signal-safe: fixed slots, atomics,
// unlink, write and _exit.
#pragma once
#include <string>

namespace pmr {

// Installs the handlers (idempotent). Call once before a long job starts.
void install_interrupt_handlers();
// 0 while running, else the first signal received (SIGINT or SIGTERM).
int interrupt_signal();

// Temporary files open right now (AtomicFile). register returns a slot (-1 when all are busy: the file is
// then only cleaned up by its destructor).
int register_temp_file(const std::string& path);
void unregister_temp_file(int slot);

}  // namespace pmr

"""pmr as a subprocess whose stderr lines are collected by a thread, so Blender's UI never blocks."""

import os
import queue
import shutil
import subprocess
import threading

from . import command


class PmrNotFound(RuntimeError):
    pass


class PmrRefused(RuntimeError):
    """pmr refused the job before rendering (bad options, a bad scene): its error line, its status."""

    def __init__(self, message, returncode):
        super().__init__(message)
        self.returncode = returncode


def resolve_program(path):
    """The pmr executable from the preferences' path (a bare name is looked up on PATH)."""
    path = os.path.expanduser(path or "pmr")
    found = shutil.which(path) if os.sep not in path else (path if os.access(path, os.X_OK) else None)
    if not found or not os.path.isfile(found):
        raise PmrNotFound(
            "pmr not found (%r): set its path in Edit > Preferences > Add-ons > pmr Light Field > "
            "pmr executable" % path)
    return found


def print_outputs(program, args, cwd=None):
    """{frame: sidecar file name} of the render `args` would run, from `pmr ... --print-outputs`
    (which renders and creates nothing). Raises RuntimeError with pmr's error line when it refuses."""
    run = subprocess.run([program] + list(args) + ["--print-outputs"], cwd=cwd, stdin=subprocess.DEVNULL,
                         capture_output=True, text=True, errors="replace")
    if run.returncode != 0:
        errors = [value for kind, value in map(command.parse_line, run.stderr.splitlines()) if kind == "error"]
        raise PmrRefused("pmr: " + (errors[0] if errors else "exited with status %d" % run.returncode),
                         run.returncode)
    return command.planned_outputs(run.stdout.splitlines())


class PmrProcess:
    """One pmr run. poll() returns the parsed lines that arrived since the last call."""

    def __init__(self, program, args, cwd=None):
        self.argv = [program] + list(args)
        # Not a terminal, so pmr prints one progress line per written frame (its terminal progress
        # line updates in place, which a pipe cannot show). stdout joins stderr: one ordered stream.
        self.proc = subprocess.Popen(self.argv, cwd=cwd, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, errors="replace", bufsize=1)
        self.lines = queue.Queue()
        self.errors, self.warnings, self.log = [], [], []
        self.progress = (None, 0, 0)  # last frame written, frames done, frames in all
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.put(line)
        self.proc.stdout.close()

    def poll(self):
        """Parses the lines that arrived; returns [(kind, value)] in order."""
        events = []
        while True:
            try:
                line = self.lines.get_nowait()
            except queue.Empty:
                break
            kind, value = command.parse_line(line)
            self.log.append(line.rstrip("\n"))
            if kind == "progress":
                self.progress = value
            elif kind == "error":
                self.errors.append(value)
            elif kind == "warning":
                self.warnings.append(value)
            events.append((kind, value))
        return events

    def finished(self):
        """True once pmr exited and every line it printed was read."""
        return self.proc.poll() is not None and not self._reader.is_alive()

    @property
    def returncode(self):
        return self.proc.returncode

    def cancel(self):
        """SIGTERM: pmr drops the frame in flight, removes its temporaries and exits 143."""
        if self.proc.poll() is None:
            self.proc.terminate()

    def wait(self, timeout=None):
        self.proc.wait(timeout)
        self._reader.join(timeout)
        return self.poll()

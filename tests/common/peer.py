"""Helpers for the tests that talk to plcrt (or a bus master) as a real peer.

Report: PASS/FAIL lines in mk/suite.sh's format under a suite prefix.
wait_for: poll a condition until it holds or a timeout passes.
Process: a child whose output lines are echoed and kept with their time.
"""
import subprocess
import threading
import time


class Report:
    """report(name, ok, detail): one line; the detail follows a failure and
    is shown in brackets under a pass (a measured figure, for instance)."""

    def __init__(self, prefix):
        self.prefix = prefix
        self.results = []

    def __call__(self, name, ok, detail=""):
        ok = bool(ok)
        self.results.append(ok)
        line = f"{'PASS' if ok else 'FAIL'}: {self.prefix}/{name}"
        print(line + (f": {detail}" if detail and not ok else ""), flush=True)
        if ok and detail:
            print(f"  ({detail})", flush=True)

    def all_passed(self):
        return all(self.results)


def wait_for(cond, timeout, step=0.002):
    """cond()'s first true value, polling every step s; after timeout s, the
    value of a last call (false if it still does not hold)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = cond()
        if v:
            return v
        time.sleep(step)
    return cond()


class Process:
    """argv run with stdout and stderr merged; each line is printed with tag
    in front and kept with its arrival time for seen() and wait()."""

    def __init__(self, argv, tag):
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.tag = tag
        self.lines = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.p.stdout:
            self.lines.append((time.monotonic(), line.rstrip()))
            print(f"   {self.tag}:", line.rstrip(), flush=True)

    def seen(self, text, since=0.0):
        """Arrival time of the first line containing text at or after since, or None."""
        return next((t for t, line in self.lines if text in line and t >= since), None)

    def wait(self, text, timeout, since=0.0):
        wait_for(lambda: self.seen(text, since) is not None, timeout)
        return self.seen(text, since)


def free_port():
    """A TCP port free on 127.0.0.1 now (for a plcrt's Modbus server)."""
    import socket
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]

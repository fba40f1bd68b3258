"""Helpers for the tests that talk to plcrt (or a bus master) as a real peer.

Report: PASS/FAIL lines in mk/suite.sh's format under a suite prefix.
wait_for: poll a condition until it holds or a timeout passes.
Process: a child whose output lines are echoed and kept with their time.
Plcrt: a plcrt started on a configuration, its output in a log file.
default_signals: the state a child should start in, whatever started us.
"""
import os
import signal
import socket
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
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                  preexec_fn=default_signals)
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


STOP_SIGNALS = (signal.SIGINT, signal.SIGQUIT, signal.SIGTERM, signal.SIGHUP)


def default_signals():
    """In a child before exec (preexec_fn): the stop signals at their default
    action and none blocked. A shell script's `make test &`, nohup or a CI
    job hands its children SIGINT and SIGQUIT (or SIGHUP) ignored, and an
    ignored signal stays ignored across exec: plcrt, which keeps an ignored
    SIGQUIT or SIGHUP ignored as nohup asks, would then not be the plcrt a
    user starts from a terminal."""
    for sig in STOP_SIGNALS:
        signal.signal(sig, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_SETMASK, [])


_ports_given = set()


def free_port():
    """A TCP port free on 127.0.0.1 now (for a plcrt's Modbus server), and
    none this process was given before: the kernel may offer a port again
    once its probe socket is closed, and two servers of one test on one
    port would be one server."""
    while True:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port not in _ports_given:
            _ports_given.add(port)
            return port


class Plcrt:
    """One plcrt process; its stdout and stderr go to WORK/NAME-N.log."""
    count = 0
    running = []

    def __init__(self, exe, cfg, work, name):
        Plcrt.count += 1
        Plcrt.running.append(self)
        self.logpath = os.path.join(work, f"{name}-{Plcrt.count}.log")
        self.log = open(self.logpath, "w+")
        self.p = subprocess.Popen([exe, "-c", cfg], stdout=self.log, stderr=self.log,
                                  preexec_fn=default_signals)
        for _ in range(200):
            if "modbus: listening" in self.output():
                return
            if self.p.poll() is not None:
                raise RuntimeError(f"plcrt exited ({self.p.returncode}): " + self.output()[-500:])
            time.sleep(0.05)
        raise RuntimeError("plcrt does not listen: " + self.output()[-500:])

    def output(self):
        self.log.flush()
        self.log.seek(0)
        return self.log.read()

    def alive(self):
        return self.p.poll() is None

    def stop(self, sig=signal.SIGTERM):
        if self.p.poll() is not None:
            return self.p.returncode
        self.p.send_signal(sig)
        try:
            return self.p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.p.kill()
            self.p.wait()
            return -999

    @classmethod
    def kill_all(cls):
        for r in cls.running:
            if r.p.poll() is None:
                r.p.kill()
                r.p.wait()

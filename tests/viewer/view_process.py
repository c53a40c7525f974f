"""What the viewer's browser tests share besides cdp.py: the skip exit, the check list, and
`avatarmap view ... --port 0` as a process whose URL is read from its standard output."""
import os
import signal
import subprocess
import sys
import time

SKIP = 77  # CTest's SKIP_RETURN_CODE for these tests


def skip(why):
    print(f"SKIPPED: {why}")
    sys.exit(SKIP)


class Checks:
    """Named checks: each prints ok/FAIL; exit() ends the test with their verdict."""

    def __init__(self):
        self.failures = []

    def __call__(self, ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        if not ok:
            self.failures.append(what)


class View:
    """`EXE view ARGS --port 0`, its URL read from its standard output, its standard error in
    WORK/view<ms>.log. A page that cannot start for want of the viewer's modules skips."""

    def __init__(self, exe, work, *args):
        self.log_path = os.path.join(work, f"view{int(time.monotonic() * 1000)}.log")
        self.log = open(self.log_path, "w")
        self.process = subprocess.Popen([exe, "view", *args, "--port", "0"],
                                        stdout=subprocess.PIPE, stderr=self.log, text=True)
        self.url = self.process.stdout.readline().strip()
        if not self.url:
            self.process.wait()
            text = open(self.log_path).read()
            if "fetch_viewer_modules" in text:
                skip("the viewer's modules are missing: " + text.strip())
            raise RuntimeError(f"avatarmap view {args} printed no URL: {text}")
        self.port = int(self.url.rsplit(":", 1)[1].strip("/"))

    def stop(self):
        """Ctrl-C; (exit code, its standard error)."""
        self.process.send_signal(signal.SIGINT)
        code = self.process.wait(20)
        self.log.close()
        return code, open(self.log_path).read()

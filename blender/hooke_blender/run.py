"""Running the hooke program on a written scene: finding it, following its progress,
stopping it, and putting its cache in place only when it finished."""

import os
import re
import shutil
import subprocess
import threading

from .scene import BakeError

PROGRESS = re.compile(r"step (\d+) of (\d+)")


def find_hooke(configured):
    """The hooke program: the extension's preference, else ``HOOKE_BIN``, else the one the
    extension's zip carries (``bin/hooke``), else ``hooke`` on the ``PATH``."""
    for candidate in (configured, os.environ.get("HOOKE_BIN")):
        if candidate:
            path = os.path.abspath(os.path.expanduser(candidate))
            if os.path.isfile(path) and os.access(path, os.X_OK):
                return path
            raise BakeError(
                f"Hooke's program '{candidate}' is not an executable file (Preferences > "
                "Add-ons > Hooke > Program, or HOOKE_BIN)"
            )
    # A zip built with `build.py --program` carries it; unzipping may drop its mode.
    bundled = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bin", "hooke")
    if os.path.isfile(bundled):
        if not os.access(bundled, os.X_OK):
            os.chmod(bundled, os.stat(bundled).st_mode | 0o755)
        return bundled
    found = shutil.which("hooke")
    if found:
        return found
    raise BakeError(
        "Hooke's program was not found: give its path in Preferences > Add-ons > Hooke > "
        "Program, set HOOKE_BIN, or put `hooke` on the PATH (cargo install --path "
        "crates/hooke-cli)"
    )


class Run:
    """``hooke run SCENE --export OUT`` in the background (``OUT`` a ``.pc2`` of the first
    body, or a folder of one per body), its progress read from its messages."""

    def __init__(self, program, scene, out):
        self.out = out
        self.lines = []
        self.fraction = 0.0
        folder = ["--format", "pc2"] if out.endswith(os.sep) else []
        self.process = subprocess.Popen(
            [program, "run", scene, "--export", out, *folder],
            cwd=os.path.dirname(scene),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            errors="replace",
        )
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.process.stderr:
            line = line.rstrip("\n")
            m = PROGRESS.search(line)
            if m:
                self.fraction = int(m.group(1)) / max(1, int(m.group(2)))
            else:
                self.lines.append(line)

    def poll(self):
        """``None`` while it runs, else its exit status."""
        return self.process.poll()

    def stop(self):
        """Stops it (as Ctrl-C would) and waits for it."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.reader.join(timeout=1)

    def warnings(self):
        """What hooke warned of in a run that finished (a surface through a collider or
        through itself, a setting it did not read, a mesh it converges on slowly), without
        the leading ``warning: ``."""
        self.reader.join(timeout=5)
        return [line[len("warning: "):] for line in self.lines if line.startswith("warning: ")]

    def failure(self):
        """What hooke said when it failed: its error lines."""
        self.reader.join(timeout=5)
        said = [line for line in self.lines if line.startswith(("error", "warning"))]
        return "\n".join(said or self.lines[-5:]) or f"exit status {self.process.returncode}"

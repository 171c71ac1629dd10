"""Type stubs of the extension module `hooke._hooke` (re-exported by `hooke`)."""

import os

from typing import Optional

import numpy as np
import numpy.typing as npt

class HookeError(Exception):
    """A scene, file or value Hooke cannot use; the message names the file and line or key."""

class DivergenceError(HookeError):
    """The state stopped making sense; the message names the step, particle and a stable dt."""

class Simulation:
    """A scene being simulated. One thread uses it at a time: a call while another thread's
    call on it runs raises HookeError."""

    def step(self, n: int = 1) -> None:
        """Advances `n` steps; KeyboardInterrupt on Ctrl-C after a whole step."""
    def advance(self, seconds: float) -> None:
        """Advances by `seconds` of simulated time (the nearest whole number of steps)."""
    def run(self) -> None:
        """Runs to the end of the scene's run, if not there yet."""
    @property
    def time(self) -> float: ...
    @property
    def steps_taken(self) -> int: ...
    @property
    def unsolved_steps(self) -> int:
        """Steps the large-step integrator ended at its iteration budget before its tolerance."""
    @property
    def total_steps(self) -> int: ...
    @property
    def every(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def integrator(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, 3) metres: a read-only copy of the state now."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """(N, 3) m/s: a read-only copy of the state now."""
    @property
    def masses(self) -> npt.NDArray[np.float64]: ...
    @property
    def pinned(self) -> npt.NDArray[np.bool_]: ...
    @property
    def springs(self) -> npt.NDArray[np.int64]:
        """(M, 2) end particles of every spring."""
    @property
    def faces(self) -> npt.NDArray[np.int64]:
        """(F, 3) particle indices of every body's surface triangles."""
    def mesh(
        self, name: str
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
        """Body name as shown: (V, 3) vertices now (a mesh body's in its file's order), (T, 3) triangles."""
    @property
    def bodies(self) -> list[tuple[str, int, int]]:
        """(name, first particle, particle count) of every body."""
    def collider_pose(
        self, k: int
    ) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
        """Collider k's (translate, rotate) now, metres and degrees; None if it does not move."""
    def render(
        self,
        width: int = 800,
        height: int = 600,
        style: str = "solid",
        yaw: float = 30.0,
        pitch: float = 22.0,
        zoom: float = 1.0,
        supersample: int = 2,
        distance: Optional[float] = None,
        color: str = "none",
        range: Optional[tuple[float, float]] = None,
        shadows: bool = True,
    ) -> npt.NDArray[np.uint8]:
        """(height, width, 3) RGB picture of the state now."""
    def export(self, path: str, format: Optional[str] = None, body: Optional[str] = None) -> str:
        """Runs the rest of the run writing `.usda`, `.pc2` or `DIR/` frames; returns a summary."""

def load(
    source: str,
    *,
    dt: Optional[float] = None,
    integrator: Optional[str] = None,
    steps: Optional[int] = None,
    duration: Optional[float] = None,
    every: Optional[int] = None,
    table: Optional[str] = None,
    threads: Optional[int] = None,
    set: Optional[dict[str, object]] = None,
    tolerance: Optional[float] = None,
    iterations: Optional[int] = None,
) -> Simulation:
    """A built-in scene, .toml scene or .w world, with the command line's overrides.

    `tolerance` (m/s) and `iterations` are the large-step integrators' stopping rule
    (`vbd`, `newton`): a step ends when its last update moved no free particle more than
    `tolerance * dt`, or after `iterations` updates."""

def scenes() -> list[tuple[str, str]]: ...
def report(dir: str | os.PathLike[str], *, quick: bool = False) -> tuple[str, list[str]]: ...

"""What a Python `step()` call costs on top of the Rust step it runs.

    python python/benches/step_overhead.py [SCENE ...]   (default: cloth-table single-spring)

For each scene: the time per step of one `step(n)` call (the Rust loop), of `n` calls of
`step()`, and the difference per call, the overhead (GIL release and re-acquisition, the
signal check, the call itself). Each round starts from the same state (200 steps in);
best of five rounds each, interleaved, so that the machine's other work moves both alike.
"""

import sys
import time

import hooke

N = 4000


def per_step(sim, batched):
    started = time.perf_counter()
    if batched:
        sim.step(N)
    else:
        for _ in range(N):
            sim.step()
    return (time.perf_counter() - started) / N


def fresh(name):
    """The scene 200 steps in: buffers paged in, workers started, the same state each time."""
    sim = hooke.load(name, steps=10**9)
    sim.step(200)
    return sim


def main(names):
    for name in names or ["cloth-table", "single-spring"]:
        batched, single = [], []
        for _ in range(5):
            batched.append(per_step(fresh(name), True))
            single.append(per_step(fresh(name), False))
        b, s = min(batched), min(single)
        print(f"{name}: step({N}) {b * 1e6:.2f} µs/step; {N} × step() {s * 1e6:.2f} µs/step; "
              f"overhead {(s - b) * 1e6:.2f} µs per call ({(s - b) / b * 100:.1f} % of a step)")


if __name__ == "__main__":
    main(sys.argv[1:])

"""Sweeps the cloth's stiffness on the round and the square table, one Ray task per point,
and plots where the cloth's lowest point ends: a stiff cloth hangs short of the floor, a
soft one drapes further down.

    python examples/sweep_ray.py                  # a local Ray cluster (or RAY_ADDRESS)
    python examples/sweep_ray.py --quick          # a small grid and short runs
    python examples/sweep_ray.py --out sweep.png

Needs `pip install ./python ray matplotlib`. On a real cluster, start it as Ray says and set
RAY_ADDRESS: nothing here changes.
"""

import argparse

import hooke


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 stiffnesses, 1 s runs")
    parser.add_argument("--out", default="sweep.png", help="the plot (PNG)")
    args = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import ray

    stiffness = [60.0, 300.0, 1500.0] if args.quick else [40.0, 80.0, 150.0, 300.0, 600.0, 1200.0, 2400.0]
    tables = {"round": "builtin:table.obj", "square": "builtin:square-table.obj"}
    grid = {"body.springs.structural.ks": stiffness, "table": list(tables.values())}
    ray.init(num_cpus=2 if args.quick else None, include_dashboard=False, log_to_driver=False)
    rows = hooke.sweep("cloth-table", grid, hooke.metrics.lowest_point, executor="ray",
                       duration=1.0 if args.quick else 3.0)
    ray.shutdown()

    fig, ax = plt.subplots(figsize=(6, 4))
    for label, table in tables.items():
        points = [(r["body.springs.structural.ks"], r["metric"]) for r in rows if r["table"] == table]
        ks, low = zip(*points)
        ax.plot(ks, low, "o-", label=f"{label} table")
        print(label, " ".join(f"ks={k:g}: {y:.4f} m" for k, y in points))
    ax.set_xscale("log")
    ax.set_xlabel("structural stiffness ks (N/m)")
    ax.set_ylabel("lowest cloth point at the end (m)")
    ax.set_title("cloth-table: how far the cloth drapes")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

"""Time the EMLA model on a trajectory-sized batch (3 actuators x 10^5 samples): value and gradients."""

from __future__ import annotations

import time

import numpy as np

from hiab_sim.emla import (
    electrical_power,
    electrical_power_partials,
    envelope_margin_partials,
    envelope_margins,
    load_emla_set,
    operating_point,
    peak_force,
    top_speed,
)


def main(n: int = 100_000, repeats: int = 5) -> None:
    rng = np.random.default_rng(0)
    for params in load_emla_set():
        f = rng.uniform(-1, 1, n) * peak_force(params)
        v = rng.uniform(-1, 1, n) * top_speed(params)
        a = rng.uniform(-2, 2, n)
        for fn in (operating_point, electrical_power, electrical_power_partials, envelope_margins,
                   envelope_margin_partials):  # fmt: skip
            start = time.perf_counter()
            for _ in range(repeats):
                fn(params, f, v, a)
            per_call = (time.perf_counter() - start) / repeats
            print(f"{params.name:9s} {fn.__name__:26s} {n} samples: {per_call * 1e3:7.2f} ms")


if __name__ == "__main__":
    main()

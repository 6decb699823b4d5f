"""amcl: filter update time against particle count (500, 5,000, 50,000) with 60 beams.

One update = motion model + likelihood-field sensor model + KLD low-variance resampling +
cluster estimate (``resample_interval`` 1, so every update resamples). The particle count is
held fixed (``min_particles == max_particles``) so the figure shows the cost per particle.
Also prints each stage alone. Single thread (numba kernels are not parallel). Target: <= 10 ms
for 5,000 particles. Prints; asserts nothing about time.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/amcl_update.py``
"""

from __future__ import annotations

import time
from functools import partial

import numpy as np

from fleetsim.localization.amcl import (
    AmclMap,
    AmclParams,
    ParticleFilter,
    ScanBeams,
    kld_resample,
    laser_likelihoods,
    particles_after_odometry,
    pose_estimate,
)

BEAMS = 60
COUNTS = (500, 5_000, 50_000)


def room_map() -> AmclMap:
    """A 20 m x 15 m room at 0.05 m with walls and a few boxes."""
    h, w = 300, 400
    occ = np.zeros((h, w), dtype=np.int8)
    occ[:4, :] = occ[-4:, :] = occ[:, :4] = occ[:, -4:] = 100
    occ[100:120, 80:200] = 100
    occ[200:260, 300:320] = 100
    occ[40:60, 250:270] = 100
    return AmclMap.from_occupancy(occ.ravel(), w, h, 0.05)


def timed(fn, repeats: int) -> float:
    """Median wall time of ``fn()`` in ms."""
    fn()  # warm-up (numba compile / caches)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def main() -> None:
    grid = room_map()
    angles = np.linspace(-np.pi, np.pi, BEAMS, endpoint=False)
    beams = ScanBeams(np.full(BEAMS, 4.0), angles, 10.0)
    print(f"amcl update time, {BEAMS} beams, likelihood_field, map {grid.width}x{grid.height}")
    print(
        f"{'particles':>10} {'update ms':>10} {'motion':>8} {'sensor':>8} {'resample':>9} "
        f"{'estimate':>9} {'us/particle':>12}"
    )
    for n in COUNTS:
        params = AmclParams(
            min_particles=n,
            max_particles=n,
            laser_max_beams=BEAMS,
            resample_interval=1,
            update_min_d=0.0,
            update_min_a=0.0,
            initial_pose_x=10.0,
            initial_pose_y=7.5,
            initial_cov_xx=4.0,
            initial_cov_yy=4.0,
        )
        rng = np.random.default_rng(0)
        pf = ParticleFilter(params, rng, grid)
        odom = np.zeros(3)

        def update(pf=pf, odom=odom) -> None:
            odom[0] += 0.3
            pf.update(odom.copy(), beams)

        repeats = 30 if n <= 5_000 else 10
        t_update = timed(update, repeats)
        parts, w = pf.particles, pf.weights
        step = np.array([0.3, 0.0, 0.1])
        t_motion = timed(
            partial(
                particles_after_odometry, parts, np.zeros(3), step, "diff", params.odom_alphas, rng
            ),
            repeats,
        )
        t_sensor = timed(
            partial(laser_likelihoods, parts, beams, np.zeros(3), grid, params, False), repeats
        )
        t_resample = timed(partial(kld_resample, parts, w, rng, 0.01, 0.99, n, n), repeats)
        t_estimate = timed(partial(pose_estimate, parts, w), repeats)
        print(
            f"{n:>10,} {t_update:>10.2f} {t_motion:>8.2f} {t_sensor:>8.2f} {t_resample:>9.2f} "
            f"{t_estimate:>9.2f} {1e3 * t_update / n:>12.3f}"
        )


if __name__ == "__main__":
    main()

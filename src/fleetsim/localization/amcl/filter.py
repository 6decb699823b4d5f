"""`ParticleFilter`: amcl's filter loop with explicit state, free of any runtime object.

State (all public, so a reset or a test can read it): ``particles`` (P, 3) ``(x, y, yaw)`` in
the global frame, ``weights`` (P,) summing to 1, the running likelihood averages ``w_slow`` and
``w_fast``, the odometry pose of the last filter update, the resample counter and the
``converged`` flag.

One `update` call is what amcl_node does for one laser scan: gate on ``update_min_d`` /
``update_min_a`` (per axis, as amcl), apply the motion model, weight with the laser model,
resample every ``resample_interval`` updates, and recompute the estimate when it resampled.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .estimate import covariance_3x3, pose_estimate
from .grid_map import AmclMap, LocalizationError
from .laser import laser_likelihoods
from .motion import odometry_delta, particles_after_odometry, wrapped_angles
from .params import AmclParams
from .resample import effective_sample_size, kld_resample
from .scan import ScanBeams

CONVERGED_DISTANCE = 0.5  # m, amcl's pf->dist_threshold


@dataclass(frozen=True)
class UpdateResult:
    """What one `ParticleFilter.update` did.

    ``updated``: the motion and sensor models ran; ``resampled``: the set was resampled;
    ``estimate_changed``: a new estimate was computed (amcl publishes ``amcl_pose`` and the
    map->odom transform then).
    """

    updated: bool
    resampled: bool
    estimate_changed: bool


def gaussian_poses(
    mean: np.ndarray, cov: np.ndarray, n: int, rng: np.random.Generator
) -> np.ndarray:
    """(n, 3) poses drawn from N(mean, cov) (amcl's ``pf_pdf_gaussian_sample``), yaw wrapped.

    ``cov`` is (3, 3), symmetric positive semi-definite (eigen-decomposed, so singular works).
    """
    cov = np.asarray(cov, dtype=np.float64)
    vals, vecs = np.linalg.eigh(0.5 * (cov + cov.T))
    if vals.min() < -1e-9 * max(1.0, abs(vals.max())):
        raise LocalizationError(f"amcl: initial covariance is not positive semi-definite: {cov}")
    z = rng.standard_normal((n, 3)) * np.sqrt(np.maximum(vals, 0.0))
    out = np.asarray(mean, dtype=np.float64) + z @ vecs.T
    out[:, 2] = wrapped_angles(out[:, 2])
    return out


class ParticleFilter:
    """Adaptive Monte Carlo localization over an `AmclMap`.

    Parameters
    ----------
    params : AmclParams
        The node's parameters.
    rng : numpy.random.Generator
        The only source of randomness.
    grid : AmclMap, optional
        The map; `update` raises until one is set.
    laser_pose : (3,) float, optional
        Laser pose ``(x, y, yaw)`` in the robot base frame.
    """

    def __init__(
        self,
        params: AmclParams,
        rng: np.random.Generator,
        grid: AmclMap | None = None,
        laser_pose: np.ndarray | tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        self.params = params
        self.rng = rng
        self.grid = grid
        self.laser_pose = np.asarray(laser_pose, dtype=np.float64)
        self.reset()

    # ----- state -----
    def reset(self) -> None:
        """Particles from the initial pose parameters; all running state cleared.

        Raises `LocalizationError` when a map is set and the initial pose lies outside it.
        """
        p = self.params
        self.w_slow = 0.0
        self.w_fast = 0.0
        self.odom_pose: np.ndarray | None = None
        self.resample_count = 0
        self.force_update = False
        self.n_effective = 0.0
        self.set_initial_pose(
            np.array([p.initial_pose_x, p.initial_pose_y, p.initial_pose_a]),
            np.diag([p.initial_cov_xx, p.initial_cov_yy, p.initial_cov_aa]),
        )

    def _set_particles(self, particles: np.ndarray, weights: np.ndarray | None = None) -> None:
        self.particles = np.ascontiguousarray(particles, dtype=np.float64)
        n = len(self.particles)
        self.weights = np.full(n, 1.0 / n) if weights is None else weights
        self.converged = self.is_converged()
        self.estimate = pose_estimate(self.particles, self.weights)

    def is_converged(self) -> bool:
        """Every particle within 0.5 m (x and y separately) of the mean (amcl's test)."""
        mean = self.particles[:, :2].mean(axis=0)
        return bool(np.all(np.abs(self.particles[:, :2] - mean) <= CONVERGED_DISTANCE))

    @property
    def particle_count(self) -> int:
        return len(self.particles)

    # ----- initialisation -----
    def set_initial_pose(self, mean: np.ndarray, cov: np.ndarray) -> None:
        """Re-seed the particles around ``mean`` (3,) with covariance ``cov`` (3, 3) or (6, 6).

        Raises `LocalizationError` when a map is set and the mean lies outside it.
        """
        mean = np.asarray(mean, dtype=np.float64).reshape(3)
        cov = np.asarray(cov, dtype=np.float64)
        if cov.size == 36:
            cov = covariance_3x3(cov)
        if not np.all(np.isfinite(mean)) or not np.all(np.isfinite(cov)):
            raise LocalizationError(f"amcl: initial pose {mean} / covariance must be finite")
        if self.grid is not None and not self.grid.contains(mean[0], mean[1]):
            g = self.grid
            raise LocalizationError(
                f"amcl: initial pose ({mean[0]:.3f}, {mean[1]:.3f}) is outside the map "
                f"(x in [{g.origin_x:.2f}, {g.origin_x + g.width * g.resolution:.2f}], "
                f"y in [{g.origin_y:.2f}, {g.origin_y + g.height * g.resolution:.2f}]); "
                "check initial_pose_x/initial_pose_y or the initialpose message frame"
            )
        self.initial_mean, self.initial_cov = mean.copy(), cov.copy()
        self._set_particles(gaussian_poses(mean, cov, self.params.max_particles, self.rng))
        self.w_slow = self.w_fast = 0.0
        self.odom_pose = None  # the next scan re-anchors odometry without a motion update

    def global_localization(self) -> None:
        """Spread ``max_particles`` uniformly over the free space (service global_localization)."""
        grid = self._require_map()
        self._set_particles(grid.random_free_poses(self.params.max_particles, self.rng))
        self.w_slow = self.w_fast = 0.0
        self.odom_pose = None

    def set_map(
        self, grid: AmclMap, mean: np.ndarray | None = None, cov: np.ndarray | None = None
    ) -> None:
        """Use a new map and re-seed around ``mean``/``cov`` (default: the current estimate)."""
        self.grid = grid
        if mean is None:
            mean = self.estimate.pose
        if cov is None:
            cov = self.initial_cov
        self.set_initial_pose(mean, cov)

    def request_nomotion_update(self) -> None:
        """Make the next `update` run the sensor model even without motion."""
        self.force_update = True

    # ----- the filter loop -----
    def _require_map(self) -> AmclMap:
        if self.grid is None:
            raise LocalizationError(
                "amcl: no map yet; start map_server (static_map service) or publish on map"
            )
        return self.grid

    def needs_update(self, odom_pose: np.ndarray) -> bool:
        """Whether a scan at ``odom_pose`` would update the filter: the first one, a move of
        more than ``update_min_d`` / ``update_min_a`` since the last update, or a forced one
        (amcl's ``update_min_*`` rule; amcl reads no more of a scan otherwise)."""
        if self.odom_pose is None or self.force_update:
            return True
        p = self.params
        d = odometry_delta(self.odom_pose, np.asarray(odom_pose, dtype=np.float64).reshape(3))
        return bool(
            abs(d[0]) > p.update_min_d or abs(d[1]) > p.update_min_d or abs(d[2]) > p.update_min_a
        )

    def update(self, odom_pose: np.ndarray, beams: ScanBeams) -> UpdateResult:
        """Process one scan taken at odometry pose ``odom_pose`` (3,) ``(x, y, yaw)``."""
        grid = self._require_map()
        pose = np.asarray(odom_pose, dtype=np.float64).reshape(3)
        if not np.all(np.isfinite(pose)):
            raise LocalizationError(f"amcl: odometry pose {pose} is not finite")
        first = self.odom_pose is None
        do_update = self.needs_update(pose)
        if not first:
            self.force_update = False
        if not do_update:
            return UpdateResult(False, False, False)
        p = self.params
        if first:
            self.resample_count = 0
        else:
            self.particles = particles_after_odometry(
                self.particles, self.odom_pose, pose, p.odom_model_type, p.odom_alphas, self.rng
            )
        self._sensor_update(grid, beams)
        self.odom_pose = pose.copy()
        self.resample_count += 1
        resampled = self.resample_count % p.resample_interval == 0
        if resampled:
            self.resample()
        if resampled or first:
            self.estimate = pose_estimate(self.particles, self.weights)
        return UpdateResult(True, resampled, resampled or first)

    def _sensor_update(self, grid: AmclMap, beams: ScanBeams) -> None:
        """Weight particles by the scan (amcl's ``pf_update_sensor``).

        The running averages track the mean scan likelihood ``sum_i w_i p(z | x_i)`` (weights
        normalised), as Probabilistic Robotics' Augmented MCL does; amcl divides this by the
        particle count once more, which ties ``w_fast / w_slow`` to KLD's changes of N.
        """
        n = self.particle_count
        if len(beams.ranges) == 0:
            return  # nothing to weigh with (all readings invalid or max range)
        vals, is_log = laser_likelihoods(
            self.particles, beams, self.laser_pose, grid, self.params, self.converged
        )
        if is_log:
            with np.errstate(divide="ignore"):
                logw = np.log(self.weights) + vals
            top = float(np.max(logw))
            if not np.isfinite(top):
                self.weights = np.full(n, 1.0 / n)
                return
            w = np.exp(logw - top)
            total = float(w.sum())
            w_avg = float(np.exp(np.log(total) + top))
        else:
            w = self.weights * vals
            total = float(w.sum())
            w_avg = total
        if not (total > 0.0 and np.isfinite(total)):
            self.weights = np.full(n, 1.0 / n)
            return
        self.weights = w / total
        a_slow, a_fast = self.params.recovery_alpha_slow, self.params.recovery_alpha_fast
        self.w_slow = w_avg if self.w_slow == 0.0 else self.w_slow + a_slow * (w_avg - self.w_slow)
        self.w_fast = w_avg if self.w_fast == 0.0 else self.w_fast + a_fast * (w_avg - self.w_fast)
        self.n_effective = effective_sample_size(self.weights)

    def resample(self) -> None:
        """KLD-adaptive low-variance resampling with random-particle recovery.

        A draw is replaced by a random free-space pose with probability
        ``max(0, 1 - w_fast / w_slow)`` (Augmented MCL). Unlike amcl, the averages are not reset
        to zero after an injection: amcl's reset re-anchors ``w_slow`` at the likelihood of the
        lost filter, after which recovery stops before the robot is found again.
        """
        p = self.params
        if p.selective_resampling and self.n_effective > 0.5 * self.particle_count:
            return
        w_diff = 0.0
        if self.w_slow > 0.0:
            w_diff = max(0.0, 1.0 - self.w_fast / self.w_slow)
        sampler = self.grid.random_free_poses if self.grid is not None else None
        new = kld_resample(
            self.particles,
            self.weights,
            self.rng,
            p.kld_err,
            p.kld_z,
            p.min_particles,
            p.max_particles,
            w_diff=w_diff if sampler is not None else 0.0,
            random_poses=sampler,
        )
        self.particles = new
        self.weights = np.full(len(new), 1.0 / len(new))
        self.converged = self.is_converged()

"""amcl's parameters, declared once: ROS name, ROS default, unit, valid range, meaning.

The names and defaults are those of the ROS 1 ``amcl`` node (wiki.ros.org/amcl), so an
``amcl.yaml`` or a launch file written for ROS loads unchanged. Where ROS uses ``-1`` to mean
"unset" (``laser_min_range``, ``laser_max_range``, ``gui_publish_rate``, ``save_pose_rate``) the
dataclass holds ``None``; ``-1`` (or any negative value) is still accepted from YAML.

Fields are declared with `fleetsim.runtime.param`; `params_from_mapping` is
`fleetsim.runtime.load_params` plus the ``-1`` -> None conversion. Constructing `AmclParams`
directly validates too (types, ranges, choices, ``min_particles <= max_particles``).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import ParameterError, did_you_mean
from fleetsim.runtime.params import ParamDict, load_params, param

ODOM_MODEL_TYPES = ("diff", "omni", "diff-corrected", "omni-corrected")
LASER_MODEL_TYPES = ("likelihood_field", "beam", "likelihood_field_prob")


#: parameters where ROS uses a negative value (-1) to mean "unset"; held as None here
UNSET_WHEN_NEGATIVE = frozenset(
    {"laser_min_range", "laser_max_range", "gui_publish_rate", "save_pose_rate"}
)


@dataclass(frozen=True)
class AmclParams:
    """Parameters of the ``amcl`` node (ROS 1 names and defaults)."""

    # --- filter ---
    min_particles: int = param(100, range=(1, None), help="minimum number of particles")
    max_particles: int = param(5000, range=(1, None), help="maximum number of particles")
    kld_err: float = param(
        0.01, range=(0.0, 1.0), help="max error between true and estimated distribution (KLD)"
    )
    kld_z: float = param(
        0.99, range=(0.0, 1.0), help="upper standard normal quantile for (1 - p) (KLD)"
    )
    update_min_d: float = param(
        0.2, unit="m", range=(0.0, None), help="translation needed before a filter update"
    )
    update_min_a: float = param(
        math.pi / 6.0,
        unit="rad",
        range=(0.0, 2.0 * math.pi),
        help="rotation needed before a filter update",
    )
    resample_interval: int = param(
        2, range=(1, None), help="filter updates between two resamplings"
    )
    transform_tolerance: float = param(
        0.1, unit="s", range=(0.0, None), help="how far into the future map->odom is dated"
    )
    recovery_alpha_slow: float = param(
        0.0, range=(0.0, 1.0), help="decay of the slow average weight (0 disables recovery)"
    )
    recovery_alpha_fast: float = param(
        0.0, range=(0.0, 1.0), help="decay of the fast average weight (0 disables recovery)"
    )
    selective_resampling: bool = param(
        False, help="resample only when the effective sample size drops below N/2"
    )
    initial_pose_x: float = param(0.0, unit="m", help="initial pose mean x (global frame)")
    initial_pose_y: float = param(0.0, unit="m", help="initial pose mean y (global frame)")
    initial_pose_a: float = param(0.0, unit="rad", help="initial pose mean yaw (global frame)")
    initial_cov_xx: float = param(
        0.5 * 0.5, unit="m^2", range=(0.0, None), help="initial pose covariance x*x"
    )
    initial_cov_yy: float = param(
        0.5 * 0.5, unit="m^2", range=(0.0, None), help="initial pose covariance y*y"
    )
    initial_cov_aa: float = param(
        (math.pi / 12.0) ** 2, unit="rad^2", range=(0.0, None), help="initial covariance yaw*yaw"
    )
    gui_publish_rate: float | None = param(
        None,
        unit="Hz",
        range=(0.0, None),
        help="max particlecloud rate (None: no limit, every update)",
    )
    save_pose_rate: float | None = param(
        0.5,
        unit="Hz",
        range=(0.0, None),
        help="rate of storing the pose in ~initial_pose_* (None: off)",
    )
    use_map_topic: bool = param(False, help="subscribe to map instead of calling static_map")
    first_map_only: bool = param(False, help="use only the first map received")
    # --- laser model ---
    laser_min_range: float | None = param(
        None, unit="m", range=(0.0, None), help="min scan range (None: the scan's)"
    )
    laser_max_range: float | None = param(
        None, unit="m", range=(0.0, None), help="max scan range (None: the scan's)"
    )
    laser_max_beams: int = param(30, range=(2, None), help="beams used per scan in the update")
    laser_z_hit: float = param(0.95, range=(0.0, 1.0), help="mixture weight of z_hit")
    laser_z_short: float = param(0.1, range=(0.0, 1.0), help="mixture weight of z_short")
    laser_z_max: float = param(0.05, range=(0.0, 1.0), help="mixture weight of z_max")
    laser_z_rand: float = param(0.05, range=(0.0, 1.0), help="mixture weight of z_rand")
    laser_sigma_hit: float = param(
        0.2, unit="m", range=(1e-9, None), help="std dev of the z_hit Gaussian"
    )
    laser_lambda_short: float = param(
        0.1, unit="1/m", range=(1e-9, None), help="exponential decay of z_short"
    )
    laser_likelihood_max_dist: float = param(
        2.0, unit="m", range=(1e-9, None), help="max obstacle distance in the likelihood field"
    )
    laser_model_type: str = param("likelihood_field", choices=LASER_MODEL_TYPES, help="laser model")
    beam_skip_distance: float = param(
        0.5, unit="m", range=(0.0, None), help="beam agrees with the map within this distance"
    )
    beam_skip_threshold: float = param(
        0.3, range=(0.0, 1.0), help="fraction of particles that must agree to keep a beam"
    )
    beam_skip_error_threshold: float = param(
        0.9, range=(0.0, 1.0), help="skipped fraction above which all beams are integrated"
    )
    do_beamskip: bool = param(False, help="beam skipping (likelihood_field_prob only)")
    # --- odometry model ---
    odom_model_type: str = param("diff", choices=ODOM_MODEL_TYPES, help="odometry motion model")
    odom_alpha1: float = param(0.2, range=(0.0, None), help="rotation noise from rotation")
    odom_alpha2: float = param(0.2, range=(0.0, None), help="rotation noise from translation")
    odom_alpha3: float = param(0.2, range=(0.0, None), help="translation noise from translation")
    odom_alpha4: float = param(0.2, range=(0.0, None), help="translation noise from rotation")
    odom_alpha5: float = param(0.2, range=(0.0, None), help="strafe noise (omni models only)")
    # --- frames ---
    odom_frame_id: str = param("odom", help="odometry frame (tf_prefix applied)")
    base_frame_id: str = param("base_link", help="robot base frame (tf_prefix applied)")
    global_frame_id: str = param("map", help="global (map) frame")
    tf_broadcast: bool = param(True, help="publish the global->odom transform")

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            object.__setattr__(self, f.name, _checked(f, getattr(self, f.name), "AmclParams"))
        if self.min_particles > self.max_particles:
            raise ParameterError(
                f"AmclParams: min_particles ({self.min_particles}) > max_particles "
                f"({self.max_particles}); set min_particles <= max_particles"
            )

    @property
    def odom_alphas(self) -> tuple[float, float, float, float, float]:
        """``(odom_alpha1, ..., odom_alpha5)``."""
        return (
            self.odom_alpha1,
            self.odom_alpha2,
            self.odom_alpha3,
            self.odom_alpha4,
            self.odom_alpha5,
        )


def _checked(f: dataclasses.Field, value: Any, source: str) -> Any:
    """Coerce ``value`` to the field's type and check its range/choices; return it."""
    meta = f.metadata
    name = f.name
    default = f.default
    unset = name in UNSET_WHEN_NEGATIVE
    if unset and value is not None:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParameterError(f"{source}: parameter '{name}' must be a number, got {value!r}")
        if value < 0:
            return None
    if value is None:
        if unset:
            return None
        raise ParameterError(f"{source}: parameter '{name}' must be set (default {default!r})")
    kind = type(default) if default is not None else float
    if kind is bool:
        if not isinstance(value, bool):
            raise ParameterError(
                f"{source}: parameter '{name}' must be true or false, got {value!r}"
            )
    elif kind is int:
        if isinstance(value, bool) or not isinstance(value, int | float) or value != int(value):
            raise ParameterError(f"{source}: parameter '{name}' must be an integer, got {value!r}")
        value = int(value)
    elif kind is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParameterError(f"{source}: parameter '{name}' must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise ParameterError(f"{source}: parameter '{name}' must be finite, got {value!r}")
    elif kind is str and not isinstance(value, str):
        raise ParameterError(f"{source}: parameter '{name}' must be a string, got {value!r}")
    choices = meta.get("choices")
    if choices is not None and value not in choices:
        raise ParameterError(
            f"{source}: unknown {name} {value!r}{did_you_mean(str(value), choices)}; "
            f"expected one of {', '.join(choices)}"
        )
    rng = meta.get("range")
    if rng is not None:
        lo, hi = rng
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            lo_s = "-inf" if lo is None else f"{lo:g}"
            hi_s = "inf" if hi is None else f"{hi:g}"
            raise ParameterError(
                f"{source}: parameter '{name}' = {value!r} is out of range [{lo_s}, {hi_s}]"
            )
    return value


def params_from_mapping(
    mapping: Mapping[str, Any] | None,
    source: str = "amcl",
    logger: logging.Logger | None = None,
) -> AmclParams:
    """Validated `AmclParams` from a ROS-style mapping (the node's private namespace).

    Negative values of `UNSET_WHEN_NEGATIVE` parameters become None; everything else is
    `fleetsim.runtime.load_params` (unknown keys warned about with a suggestion, old names
    accepted, ``source`` named in every error).
    """
    values = ParamDict.copy_of(mapping)  # keeps where each value was set, for messages
    for key in UNSET_WHEN_NEGATIVE:
        v = values.get(key)
        if isinstance(v, int | float) and not isinstance(v, bool) and v < 0:
            values[key] = None
    try:
        return load_params(AmclParams, values, where=source, logger=logger)
    except ParameterError as err:
        msg = str(err).replace("AmclParams:", f"{source}:", 1)
        raise ParameterError(msg) from None

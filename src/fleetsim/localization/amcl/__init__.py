"""amcl: adaptive Monte Carlo localization (ROS 1 ``amcl``), as batched kernels and a filter.

Public API:

- `AmclParams`, `params_from_mapping`: the node's parameters (ROS names and defaults).
- `AmclMap`: the map in amcl's three cell states, with its distance field and free cells.
- `ParticleFilter`: the filter with explicit state (``particles`` (P, 3), ``weights`` (P,));
  `ParticleFilter.update` processes one scan, `beams_from_scan` conditions a scan for it.
- Kernels: `particles_after_odometry`, `endpoint_likelihoods`, `beam_model_weights`,
  `systematic_resample_indices`, `kld_sample_limits`, `kld_resample`, `cluster_labels`,
  `pose_estimate`.
"""

from .estimate import PoseEstimate, covariance_3x3, covariance_6x6, pose_estimate
from .filter import ParticleFilter, UpdateResult, gaussian_poses
from .grid_map import AmclMap, LocalizationError, distances_to_obstacles
from .histogram import cluster_labels, pose_bin_keys
from .laser import beam_model_weights, endpoint_likelihoods, laser_likelihoods, ranges_from_map
from .motion import particles_after_odometry
from .params import AmclParams, params_from_mapping
from .resample import kld_resample, kld_sample_limits, systematic_resample_indices
from .scan import ScanBeams, beams_from_scan

__all__ = [
    "AmclMap",
    "AmclParams",
    "LocalizationError",
    "ParticleFilter",
    "PoseEstimate",
    "ScanBeams",
    "UpdateResult",
    "beam_model_weights",
    "beams_from_scan",
    "cluster_labels",
    "covariance_3x3",
    "covariance_6x6",
    "distances_to_obstacles",
    "endpoint_likelihoods",
    "gaussian_poses",
    "kld_resample",
    "kld_sample_limits",
    "laser_likelihoods",
    "params_from_mapping",
    "particles_after_odometry",
    "pose_bin_keys",
    "pose_estimate",
    "ranges_from_map",
    "systematic_resample_indices",
]

"""Motion primitives mixed into MPPI's sampled batch (a fleetsim addition to Nav2's MPPI).

Nav2 samples every control sequence as the current one plus Gaussian noise drawn
independently at each time step. Averaged over a trajectory that noise is small (``wz_std``
0.4 rad/s over 20 steps has a mean of std 0.09 rad/s), so the batch never contains a
manoeuvre of two phases, such as "turn 0.5 rad on the spot, then drive": when the robot faces
an obstacle with the path beside it (a BARN jackal heading 0.5 rad off a 0.8 m gap, world
141), every forward sample collides, a turn alone does not lower any critic's cost, and MPPI
settles on standing still for good. Nav2's answer is the RotationShimController in front of
MPPI, which only turns the robot when the path is more than 45 degrees off.

Here a few deterministic sequences replace the last samples of the batch in every
iteration: stand still, drive straight, turn on the spot, and turn on the spot for a while
then drive straight, in both directions. They are rolled out and scored by the same kernels
and critics as the noised samples, so they win only when they score better; the softmax then
moves the sequence onto them and the noise explores around it in the next cycles (the
sampling-based planners' usual remedy for a local minimum, as DWA samples turns in place).
"""

from __future__ import annotations

import numpy as np

#: s of turning on the spot before driving straight, in the turn-then-drive primitives
TURN_TIMES = (0.15, 0.3, 0.5, 0.8, 1.2)
#: fractions of vx_max the straight parts drive at
SPEED_FRACTIONS = (0.5, 1.0)


def primitive_sequences(time_steps: int, dt: float, vx_max: float, wz_max: float) -> np.ndarray:
    """The primitives as (K, T, 3) control sequences (vx m/s, vy m/s, wz rad/s).

    ``time_steps`` T and ``dt`` (s) are the controller's; the turns run at half ``wz_max``
    (rad/s, a turn the acceleration limits let a sample reach within a few steps), the drives
    at `SPEED_FRACTIONS` of ``vx_max`` (m/s, >= 0). Order: stand still, drive straight at each
    speed, turn on the spot each way, then for each turn time, direction and speed a turn
    followed by a straight drive.
    """
    wz = 0.5 * wz_max
    speeds = [f * max(vx_max, 0.0) for f in SPEED_FRACTIONS]
    out = [np.zeros((time_steps, 3))]
    for v in speeds:
        seq = np.zeros((time_steps, 3))
        seq[:, 0] = v
        out.append(seq)
    for sign in (1.0, -1.0):
        seq = np.zeros((time_steps, 3))
        seq[:, 2] = sign * wz
        out.append(seq)
    for turn in TURN_TIMES:
        n = min(max(1, round(turn / dt)), time_steps - 1)
        for sign in (1.0, -1.0):
            for v in speeds:
                seq = np.zeros((time_steps, 3))
                seq[:n, 2] = sign * wz
                seq[n:, 0] = v
                out.append(seq)
    return np.stack(out)


def set_primitive_rows(noise: np.ndarray, sequence: np.ndarray, primitives: np.ndarray) -> None:
    """Overwrite the last K rows of ``noise`` (B, T, 3) in place so that ``sequence`` (T, 3)
    plus them gives the (K, T, 3) ``primitives`` (those rows are the primitives' for good; no
    copy of the batch). With K >= B, only the first B primitives are used."""
    k = min(primitives.shape[0], noise.shape[0])
    if k:
        np.subtract(primitives[:k], sequence, out=noise[noise.shape[0] - k :])

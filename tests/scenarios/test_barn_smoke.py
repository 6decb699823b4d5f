"""BARN smoke test: one BARN world through the whole pipeline for a few sim seconds.

The shipped ``barn.launch`` (simulator on ``world_3.world``, the jackal, move_base, send_goals)
runs for 8 s of sim time; the jackal must have left its start towards the goal, without a
contact. Success rates are ``benchmarks/barn.py``'s job. Also checks the benchmark's protocol
arithmetic (reference path, optimal time, metric) against the README's definitions.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import barn


def test_reference_path_and_metric_follow_the_readme():
    path = barn.path_from_grid(np.array([[0, 0], [30, 0]]))
    assert np.allclose(path[0], barn.START) and np.allclose(path[-1], barn.GOAL)
    assert np.allclose(path[1], (-4.575, 5.075)) and np.allclose(path[2], (-0.075, 5.075))
    length = math.dist(barn.START, path[1]) + 4.5 + math.dist(path[2], barn.GOAL)
    assert barn.optimal_time_of(path) == pytest.approx(length / 2.0)
    assert barn.metric_of(True, 1.0, 10.0) == pytest.approx(0.5)  # clipped up to 2 x optimal
    assert barn.metric_of(True, 40.0, 10.0) == pytest.approx(0.25)
    assert barn.metric_of(True, 500.0, 10.0) == pytest.approx(0.125)  # clipped to 8 x optimal
    assert barn.metric_of(False, 30.0, 10.0) == 0.0


def test_the_tuning_split_is_the_first_half_by_number(tmp_path):
    for w in (3, 9, 15, 21, 27, 153, 159, 165, 171, 177):
        (tmp_path / f"world_{w}.world").write_text("")
    assert barn.half_worlds(tmp_path, "tuning") == [3, 9, 15, 21, 27]
    assert barn.half_worlds(tmp_path, "held-out") == [153, 159, 165, 171, 177]
    assert barn.split_name(tmp_path, "held-out") == "held-out half of the split, worlds 153-177 (5)"
    if barn.BARN_DIR.is_dir():  # the shared worlds: tuned on 3-147, held out 153-297
        tuning, held = (
            barn.half_worlds(barn.BARN_DIR, "tuning"),
            barn.half_worlds(barn.BARN_DIR, "held-out"),
        )
        assert (tuning[0], tuning[-1], held[0], held[-1]) == (3, 147, 153, 297)


def test_summary_rates():
    r = [
        barn.RunResult(3, outcome, 10.0, 5.0, 0.25 if outcome == "success" else 0.0, 0.5, 1.0)
        for outcome in ("success", "success", "collision", "aborted")
    ]
    s = barn.summary(r)
    assert (s["success"], s["collision"], s["timeout"]) == (0.5, 0.25, 0.25)
    assert s["metric"] == pytest.approx(0.125)


@pytest.mark.scenario
def test_jackal_sets_off_towards_the_goal_in_world_3():
    r = barn.run_world(3, time_limit=6.0)
    assert r.outcome in ("timeout", "success"), r  # no collision, no aborted goal
    start_gap = math.dist(barn.START, barn.GOAL)
    assert r.final_gap < start_gap - 1.0, r  # at least 1 m closer to the goal


def test_half_names_and_the_summary_of_each_half(tmp_path, capsys):
    for w in (3, 9, 153, 159):
        (tmp_path / f"world_{w}.world").write_text("")
    assert barn.half_name("heldout") == barn.half_name("held-out") == "held-out"
    assert barn.half_name("Tuning") == "tuning"
    with pytest.raises(Exception, match="'test' is not a half of the split; use one of"):
        barn.half_name("test")
    assert [barn.half_of(tmp_path, w) for w in (3, 159, 4)] == ["tuning", "held-out", None]
    runs = [
        barn.RunResult(w, outcome, 10.0, 5.0, 0.25 if outcome == "success" else 0.0, 0.5, 1.0)
        for w, outcome in ((3, "success"), (9, "success"), (153, "success"), (159, "timeout"))
    ]
    barn.print_by_half(runs, tmp_path)
    out = capsys.readouterr().out
    assert "tuning half of the split, worlds 3-9 (2): runs 2: success 100.0 %" in out
    assert "held-out half of the split, worlds 153-159 (2): runs 2: success 50.0 %" in out
    barn.print_by_half(runs[:2], tmp_path)  # one half only: no per-half lines
    assert "half of the split" not in capsys.readouterr().out

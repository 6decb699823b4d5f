"""Batch specs: value sweeps, seeds, and every bad input reported before any run."""

from pathlib import Path

import pytest

from fleetsim.batch.spec import (
    BatchSpec,
    declared_args,
    load_spec,
    parse_cli_args,
    parse_seeds,
    parse_values,
    validate,
)
from fleetsim.errors import BatchError

FIXTURES = Path(__file__).parent / "fixtures"


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("3..6", ["3", "4", "5", "6"]),
        ("-1..1", ["-1", "0", "1"]),
        ("0.1..0.5:0.2", ["0.1", "0.3", "0.5"]),
        ("0.1..0.35:0.1", ["0.1", "0.2", "0.3"]),
        ("a,b", ["a", "b"]),
        ([0.2, 0.4, True], ["0.2", "0.4", "true"]),
        (7, ["7"]),
        ("../data/barn", ["../data/barn"]),  # a path, not a range
    ],
)
def test_values(value, expected):
    assert parse_values("x", value, "here") == expected


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("5..3", r"arg 'x': range '5..3' is empty"),
        ("1..x", r"arg 'x': malformed range '1..x'"),
        ("3..", r"malformed range '3..'"),
        ("0..1:0", r"range '0..1:0' is empty"),
        ([], r"arg 'x' sweeps no values \(an empty sweep\)"),
        ("a,,b", r"empty value in 'a,,b'"),
        ([1, 1], r"repeats a value"),
        ([{"a": 1}], r"is not a number or a string"),
    ],
)
def test_bad_values_name_the_arg_and_the_value(value, message):
    with pytest.raises(BatchError, match=message):
        parse_values("x", value, "here")


def test_seeds():
    assert parse_seeds("0..3", "s") == [0, 1, 2, 3]
    assert parse_seeds([5, 2], "s") == [5, 2]
    with pytest.raises(BatchError, match="seeds must be integers"):
        parse_seeds("a,b", "s")
    with pytest.raises(BatchError, match="seeds must be >= 0"):
        parse_seeds(-2, "s")


def test_cli_args():
    assert parse_cli_args(["speed=0.1,0.2", "world=3..4"]) == {
        "speed": ["0.1", "0.2"],
        "world": ["3", "4"],
    }
    with pytest.raises(BatchError, match="not of the form NAME=V1,V2"):
        parse_cli_args(["speed"])
    with pytest.raises(BatchError, match="'speed' is given twice"):
        parse_cli_args(["speed=1", "speed=2"])


def test_declared_args_of_xml_and_shipped_scenarios():
    assert declared_args(FIXTURES / "tiny.launch") == {"speed", "turn", "fault"}
    assert {"world", "barn_dir", "gui"} <= declared_args(
        Path(__file__).parents[2] / "src/fleetsim/assets/launch/barn.launch"
    )


def test_cross_product_in_a_stable_order():
    spec = BatchSpec(
        scenarios=["tiny.launch"],
        args={"turn": ["0", "1"], "speed": ["0.1", "0.2"]},
        seeds=[0, 1],
        workdir=FIXTURES,
    )
    runs = validate(spec)
    assert len(runs) == 8
    assert [r.index for r in runs] == list(range(8))
    assert runs[0].args == (("speed", "0.1"), ("turn", "0")) and runs[1].seed == 1
    assert len({r.run_id for r in runs}) == 8
    # a run's id is what it runs, not where it is in the sweep
    assert runs[3].run_id == validate(spec)[3].run_id


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (dict(scenarios=["no_such"]), r"unknown scenario 'no_such'"),
        (dict(scenarios=["barm"]), r"unknown scenario 'barm'.*did you mean 'barn'"),
        (
            dict(scenarios=["tiny.launch"], args={"sped": ["1"]}),
            r"scenario 'tiny.launch' .* declares no arg 'sped' \(did you mean 'speed'\?\); "
            r"it declares fault, speed, turn",
        ),
        (dict(scenarios=[]), r"no scenario to run \(an empty sweep\)"),
        (dict(scenarios=["tiny.launch"], seeds=[]), r"no seeds \(an empty sweep\)"),
        (dict(scenarios=["tiny.launch"], duration=0.0), r"duration must be > 0 s"),
        (dict(scenarios=["tiny.launch"], metrics="bran"), r"unknown scenario metrics 'bran'"),
    ],
)
def test_bad_specs_fail_validation(spec, message):
    with pytest.raises(BatchError, match=message):
        validate(BatchSpec(workdir=FIXTURES, **spec))


def test_every_combination_is_loaded_before_any_run(tmp_path: Path):
    (tmp_path / "two.launch").write_text(
        '<launch><arg name="f"/>\n<rosparam file="$(arg f)" command="load"/></launch>\n'
    )
    (tmp_path / "ok.yaml").write_text("a: 1\n")
    spec = BatchSpec(scenarios=["two.launch"], args={"f": ["ok.yaml", "gone.yaml"]})
    spec.workdir = tmp_path
    with pytest.raises(BatchError, match=r"two.launch' with \{'f': 'gone.yaml'\}"):
        validate(spec)


def test_spec_file(tmp_path: Path):
    f = tmp_path / "sweep.yaml"
    f.write_text(
        "scenarios: [tiny.launch]\nargs: {speed: 0.1..0.3:0.1, turn: [0, 1]}\nseeds: 0..2\n"
        "duration: 2\ntimeout: 30\n"
    )
    spec = load_spec(f)
    assert spec.args == {"speed": ["0.1", "0.2", "0.3"], "turn": ["0", "1"]}
    assert (spec.seeds, spec.duration, spec.timeout, spec.workdir) == (
        [0, 1, 2],
        2.0,
        30.0,
        tmp_path,
    )
    f.write_text("scenarios: [tiny.launch]\nseed: 1\n")
    with pytest.raises(BatchError, match=r"sweep.yaml: unknown key 'seed' \(did you mean 'seeds'"):
        load_spec(f)
    f.write_text("scenarios: [tiny.launch]\nargs: {speed: 1..}\n")
    with pytest.raises(BatchError, match=r"sweep.yaml: arg 'speed': malformed range '1..'"):
        load_spec(f)
    f.write_text("scenarios: [tiny.launch]\nduration: long\n")
    with pytest.raises(BatchError, match=r"'duration' must be a number, got 'long'"):
        load_spec(f)
    with pytest.raises(BatchError, match="does not exist"):
        load_spec(tmp_path / "nope.yaml")


def test_scenario_metrics_check_every_combination():
    barn_dir = str(Path(__file__).resolve().parents[2].parent / "shared" / "data" / "barn")
    spec = BatchSpec(scenarios=["barn"], args={"world": ["3", "4"], "barn_dir": [barn_dir]})
    with pytest.raises(BatchError, match=r"BARN world 4: .*world_4.world does not exist"):
        validate(spec)


def test_declared_args_of_a_yaml_launch_file(tmp_path: Path):
    f = tmp_path / "two.launch.yaml"
    f.write_text(
        "launch:\n- arg: {name: speed, default: '0.2'}\n- arg: {name: world}\n"
        "- let: {name: fixed, value: '1'}\n"
    )
    assert declared_args(f) == {"speed", "world"}

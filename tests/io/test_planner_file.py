import json
import math
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contourgrasp as cg
from contourgrasp.io.planner_file import PlannerFileError, load_planner, parse_planner, planner_names
from contourgrasp.synthesis import search
from contourgrasp.validation import with_options


def test_presets_load_and_paper_is_the_thesis():
    assert {"paper", "default"} <= set(planner_names())
    paper = load_planner("paper")
    assert paper.options.search.harmonics == 4 and paper.options.search.grid.xy_step == 0.05
    assert paper.options.search.grid.d_min == 0.015
    assert paper.options.search.grid.yaw_step == pytest.approx(math.radians(2.0))
    assert dict(paper.settings)["depth_mode"] == paper.options.perception.depth_mode == "max"


@pytest.mark.parametrize("name", ["paper", "default"])
def test_preset_options_are_accepted_by_synthesis(name):
    options = with_options(load_planner(name).options.search, {"xy_step": 0.03, "yaw_step": math.radians(15)},
                           what="test")
    plan = search(cg.example_contour("can"), cg.load_hand("three-finger"), options)
    assert plan.grid.xy_step == 0.03


def test_a_file_round_trips_its_options(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('name = "mine"\nharmonics = "adaptive"\nd_max = [0.1, 0.12]\nfootprint = true\n'
                    'finger_thickness = true\nclearance = 0.005\n')
    planner = load_planner(str(path))
    assert planner.name == "mine"
    assert dict(planner.settings) == {"harmonics": "adaptive", "d_max": (0.1, 0.12), "footprint": True,
                                      "finger_thickness": True, "clearance": 0.005}
    assert planner.options.perception.footprint is True and planner.options.search.grid.d_max == (0.1, 0.12)
    assert planner.options.search.safeguards.clearance == 0.005 and planner.options.search.harmonics == "adaptive"


@pytest.mark.parametrize("text, field", [
    ('name = "x"\nxy_step = -0.01', "xy_step"),
    ('name = "x"\nharmonics = "many"', "harmonics"),
    ('name = "x"\ncurvature = "wiggly"', "curvature"),
    ('name = "x"\nfootprint = "yes"', "footprint"),
    ('name = "x"\nspeed = 3', "speed"),
    ('harmonics = 4', "name"),
    ('name = "x"\nfinger_thickness = 1', "finger_thickness"),
    ('name = "x"\ndescent = 1', "descent"),
    ('name = "x"\ngrasp_height = "high"', "grasp_height"),
    ('name = "x"\ngrasp_height = -0.1', "grasp_height: a grasp height must be in"),
    ('name = "x"\nslice_contour = "sometimes"', 'slice_contour: must be true, false, "unbalanced" or "hand", got \'sometimes\''),
    ('name = "x"\nslice_contour = 1', 'slice_contour: must be true, false, "unbalanced" or "hand", got 1'),
    ('name = "x"\nsmall_objects = "yes"', "small_objects"),
    ('name = "x"\nlow_objects = 1', "low_objects"),
    ('name = "x"\nmax_imbalance = "hands"', "max_imbalance"),
    ('name = "x"\nmax_imbalance = 1.5', "max_imbalance"),
    ('name = "x"\napproaches = "front"', "approaches: approaches must be one of"),
    ('name = "x"\napproaches = "top+top"', "approaches: approaches names a kind twice"),
    ('name = "x"\napproaches = 3', "approaches"),
])
def test_bad_files_name_the_field(text, field):
    with pytest.raises(PlannerFileError, match=f"mine.toml: {field}"):
        parse_planner(text, source="mine.toml")


def test_unknown_planner_and_unreadable_file():
    with pytest.raises(PlannerFileError, match="unknown planner 'fastest'"):
        load_planner("fastest")
    with pytest.raises(PlannerFileError, match="cannot read"):
        load_planner("/nonexistent/planner.toml")


def test_cli_takes_the_planner_and_lets_flags_override_it(tmp_path, capsys):
    from contourgrasp.cli import main

    out = tmp_path / "plan.json"
    args = ["synth", "--contour", "example:case", "--hand", "three-finger", "--yaw-step-deg", "15", "--out", str(out)]
    assert main([*args, "--planner", "paper"]) == 0
    assert json.loads(out.read_text())["grid"]["xy_step"] == 0.05
    assert main([*args, "--planner", "paper", "--xy-step", "0.03"]) == 0
    assert json.loads(out.read_text())["grid"]["xy_step"] == 0.03
    assert main([*args]) == 0  # the default planner
    assert json.loads(out.read_text())["grid"]["xy_step"] == load_planner("default").options.search.grid.xy_step
    out.unlink()
    assert main([*args, "--planner", "nosuch"]) == 2
    assert "unknown planner 'nosuch'" in capsys.readouterr().err and not out.exists()


def test_cli_harmonics_takes_a_count_or_adaptive(tmp_path, capsys):
    from contourgrasp.cli import main

    out = tmp_path / "plan.json"
    args = ["synth", "--contour", "example:stone2", "--yaw-step-deg", "15", "--out", str(out)]
    assert main([*args, "--harmonics", "adaptive"]) == 0
    assert json.loads(out.read_text())["efd"]["harmonics"] == 8  # the thesis's count for stone 2
    out.unlink()
    assert main([*args, "--harmonics", "many"]) == 2
    assert "positive integer or 'adaptive', got 'many'" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("text, message", [
    ('xy_step = 1e-4\nd_max = 1.0', "the search grid would have 7.2e+10 poses (x 20001 × y 20001 × yaw 180); "
                                    "at most 1,000,000"),
    ("yaw_step = 1e-9", "the search grid would have"),
    ("d_max = 1e6", "d_max"),
    ("harmonics = 1000000", "harmonics: Input should be less than or equal to 100"),
    ("friction = 1e300", "friction"),
    ("clearance = 1e300", "clearance"),
])
def test_unbounded_work_in_a_planner_file_is_refused_naming_the_limit(text, message):
    with pytest.raises(PlannerFileError, match=re.escape(f"p.toml: {message}")):
        parse_planner(f'name = "x"\n{text}\n', source="p.toml")


def test_a_planner_file_error_is_a_planner_error():
    assert issubclass(PlannerFileError, cg.PlannerError)


@pytest.mark.parametrize("content", [bytes(range(256)), 'name = "x"'.encode("utf-16")])
def test_a_binary_or_utf16_planner_is_one_planner_file_error_naming_it(tmp_path, content):
    path = tmp_path / "p.toml"
    path.write_bytes(content)
    with pytest.raises(PlannerFileError, match=f"{re.escape(str(path))}: cannot read planner file \\(not UTF-8"):
        load_planner(path)


def test_deeply_nested_planner_toml_is_one_planner_file_error():
    with pytest.raises(PlannerFileError, match="p.toml: not valid TOML"):
        parse_planner("x = " + "{a = " * 50_000 + "1" + "}" * 50_000, source="p.toml")


@settings(max_examples=100, deadline=None)
@given(content=st.one_of(st.binary(max_size=300), st.text(max_size=300).map(str.encode),
                         st.builds(lambda key, value: f'name = "x"\n{key} = {value}\n'.encode(),
                                   st.sampled_from(["xy_step", "yaw_step", "d_max", "d_min", "harmonics", "friction",
                                                    "clearance", "quality_gain", "max_imbalance", "refine"]),
                                   st.sampled_from(["1e-300", "1e300", "-1", "0", "nan", "inf", "1000000", '"x"',
                                                    "[0.1, 1e300]", "true", "0.05"]))))
def test_fuzz_load_planner_on_random_bytes_gives_a_planner_or_a_planner_file_error(tmp_path_factory, content):
    path = tmp_path_factory.mktemp("fuzz") / "p.toml"
    path.write_bytes(content)
    try:
        planner = load_planner(path)
    except PlannerFileError as err:
        assert str(err).startswith(str(path)) and "\n" not in str(err)
        return
    assert planner.name == "x"


def test_the_slice_contour_is_a_flag_unbalanced_or_the_hands():
    planner = parse_planner('name = "x"\nslice_contour = "unbalanced"', source="mine.toml")
    assert planner.options.scene.slice_contour == "unbalanced"
    assert parse_planner('name = "x"\nslice_contour = "hand"').options.scene.slice_contour == "hand"
    with pytest.raises(PlannerFileError, match="mine.toml.*slice_contour"):
        parse_planner('name = "x"\nslice_contour = "sometimes"', source="mine.toml")


def test_the_scene_keys_are_plan_options_not_search_options():
    planner = parse_planner('name = "x"\ndescent = true\ngrasp_height = 0.05\nslice_contour = false\n'
                            'closing_sweep = true\nsmall_objects = true\nxy_step = 0.02', source="mine.toml")
    assert planner.options.scene.grasp_height == 0.05 and planner.options.scene.descent is True
    assert planner.options.search.small_objects is True  # the rule is the search's
    assert planner.options.search.grid.xy_step == 0.02

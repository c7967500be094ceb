import contextlib
import io
import json
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contourgrasp import example_contour
from contourgrasp.cli import main

FAST = ["--yaw-step-deg", "10"]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_hands_lists_the_presets(capsys):
    code, out, _ = run(capsys, "hands")
    assert code == 0
    for name in ["five-finger-linear", "five-finger-curved-thumb", "three-finger"]:
        assert name in out


def test_synth_writes_json_and_png(tmp_path, capsys):
    out_json, out_png = tmp_path / "plan.json", tmp_path / "plan.png"
    # --max-imbalance 1: with the balance, the exact evaluation stops at candidates too few for 4 distinct alternatives
    code, out, err = run(capsys, "synth", "--contour", "example:case", "--hand", "three-finger", *FAST,
                         "--out", out_json, "--plot", out_png, "--top-k", "4", "--d-max", "0.1", "0.12",
                         "--max-imbalance", "1")
    assert code == 0, err
    data = json.loads(out_json.read_text())
    assert data["hand"] == "three-finger" and len(data["alternatives"]) == 4
    assert data["grid"]["d_max"] == [0.1, 0.12]
    assert out_png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "pose x=" in out


def test_synth_prints_json_without_out(tmp_path, capsys):
    path = tmp_path / "c.npy"
    np.save(path, example_contour("can"))
    code, out, _ = run(capsys, "synth", "--contour", path, "--hand", "three-finger", *FAST)
    assert code == 0
    assert json.loads(out)["curvature_mode"] == "paper"


def test_efd_command_writes_the_harmonics_figure(tmp_path, capsys):
    code, out, _ = run(capsys, "efd", "--contour", "example:stone1", "--harmonics", "1", "2", "4", "8",
                       "--plot", tmp_path / "efd.png")
    assert code == 0
    assert out.count("harmonics:") == 4
    assert (tmp_path / "efd.png").stat().st_size > 1000


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "content, code, message",
    [
        (None, 2, "contour file not found"),
        ("x,y\n0,0\n0.1,0.1\n", 2, "at least 3 distinct points"),
        ("0,0\nnan,0.1\n0.1,0\n", 2, "not finite"),
        ("0,0\n0.05,0.05\n0.1,0.1\n", 2, "no area"),
        ("0,0\n0.1,0.1\n0.1,0\n0,0.1\n", 2, "self-intersecting"),
        ("0,0\n0.001,0\n0.001,0.001\n0,0.001\n", 3, "too small"),
    ],
)
def test_bad_contours_give_one_line_and_no_output(tmp_path, capsys, content, code, message):
    contour = tmp_path / "c.csv" if content is None else write(tmp_path, "c.csv", content)
    result, _, err = run(capsys, "synth", "--contour", contour, "--hand", "five-finger-linear", *FAST,
                         "--out", tmp_path / "plan.json", "--plot", tmp_path / "plan.png")
    assert result == code
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "plan.json").exists() and not (tmp_path / "plan.png").exists()
    assert [p.name for p in tmp_path.iterdir()] == ([] if content is None else ["c.csv"])


def test_millimetre_contour_is_warned_and_infeasible(tmp_path, capsys):
    path = tmp_path / "mm.csv"
    np.savetxt(path, example_contour("can") * 1000, delimiter=",")
    code, _, err = run(capsys, "synth", "--contour", path, *FAST, "--out", tmp_path / "p.json")
    assert code == 3
    lines = err.strip().splitlines()
    assert len(lines) == 2
    assert "warning" in lines[0] and "millimetres" in lines[0]
    assert "larger than the hand" in lines[1]
    assert not (tmp_path / "p.json").exists()


def test_bad_hand_file(tmp_path, capsys):
    hand = write(tmp_path, "h.toml", 'name = "x"\nmin_touching = 1\n[[fingers]]\nname = "a"\nstart = [0, 0]\n'
                                      'closing_direction = [0, 1]\ntravel = -1\n')
    code, _, err = run(capsys, "synth", "--contour", "example:can", "--hand", hand, *FAST)
    assert code == 2
    assert f"{hand}: fingers[0] (a).travel" in err


def test_missing_output_directory(tmp_path, capsys):
    code, _, err = run(capsys, "synth", "--contour", "example:can", "--hand", "three-finger", *FAST,
                       "--out", tmp_path / "nope" / "p.json")
    assert code == 2 and "does not exist" in err


def test_bad_option_values_exit_2(capsys):
    assert main(["synth", "--contour", "example:can", "--xy-step", "-1"]) == 2


@pytest.mark.parametrize("argv, line", [
    (["synth", "--contour", "example:can", "--xy-step", "abc"],
     "contourgrasp synth: error: argument --xy-step: must be a positive number, got 'abc' (see contourgrasp synth --help)"),
    (["synth", "--contour", "example:can", "--friction", "nan"],
     "contourgrasp synth: error: argument --friction: must be a number >= 0, got 'nan' (see contourgrasp synth --help)"),
    (["synth", "--contour", "example:can", "--max-imbalance", "hands"],
     "contourgrasp synth: error: argument --max-imbalance: must be a number >= 0 or 'hand', got 'hands' "
     "(see contourgrasp synth --help)"),
    (["synth", "--contour", "example:can", "--harmonics", "many"],
     "contourgrasp synth: error: argument --harmonics: must be a positive integer or 'adaptive', got 'many' "
     "(see contourgrasp synth --help)"),
    (["plan", "--depth", "d.npy", "--intrinsics", "i.yaml", "--approach-offset=-inf"],
     "contourgrasp plan: error: argument --approach-offset: must be a finite number, got '-inf' "
     "(see contourgrasp plan --help)"),
    (["bench", "--trials", "9" * 60 + "x"],
     f"contourgrasp bench: error: argument --trials: must be a positive integer, got '{'9' * 37}...' "
     "(see contourgrasp bench --help)"),
    (["synth"], "contourgrasp synth: error: the following arguments are required: --contour "
                "(see contourgrasp synth --help)"),
    (["nope"], "contourgrasp: error: argument command: invalid choice: 'nope' (choose from 'hands', 'synth', 'plan', "
               "'doctor', 'bench', 'calibrate', 'hand-from-model', 'ros', 'efd') (see contourgrasp --help)"),
])
def test_argument_errors_are_one_line_naming_help(capsys, argv, line):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "" and err == line + "\n"


def test_a_plot_directory_leaves_the_json_output_unchanged(tmp_path, capsys):
    out = tmp_path / "out.json"
    out.write_text("old")
    (tmp_path / "adir").mkdir()
    code, _, err = run(capsys, "synth", "--contour", "example:can", *FAST, "--out", out, "--plot", tmp_path / "adir")
    assert code == 2 and err.strip().splitlines() == [f"contourgrasp: error: {tmp_path / 'adir'}: cannot write, it is a "
                                                      "directory"]
    assert out.read_text() == "old"


def test_the_same_output_twice_is_refused(tmp_path, capsys):
    target = tmp_path / "X"
    code, _, err = run(capsys, "synth", "--contour", "example:can", *FAST, "--out", target, "--plot", target)
    assert code == 2 and "given twice as an output" in err and len(err.strip().splitlines()) == 1
    assert not target.exists()


@pytest.mark.parametrize("option", ["--out", "--plot"])
def test_an_output_never_overwrites_an_input(tmp_path, capsys, option):
    contour = tmp_path / "c.csv"
    np.savetxt(contour, example_contour("can"), delimiter=",")
    before = contour.read_bytes()
    code, _, err = run(capsys, "synth", "--contour", contour, *FAST, option, contour)
    assert code == 2 and "would overwrite the input file" in err and contour.read_bytes() == before


def test_an_existing_output_keeps_its_mode(tmp_path, capsys):
    out = tmp_path / "out.json"
    out.write_text("old")
    out.chmod(0o600)
    assert run(capsys, "synth", "--contour", "example:can", *FAST, "--out", out)[0] == 0
    assert stat.S_IMODE(out.stat().st_mode) == 0o600 and json.loads(out.read_text())["hand"]


def test_repeated_synth_runs_write_identical_plans(tmp_path, capsys):
    plans = []
    for name in ("a.json", "b.json"):
        assert run(capsys, "synth", "--contour", "example:stone2", *FAST, "--out", tmp_path / name)[0] == 0
        plans.append({k: v for k, v in json.loads((tmp_path / name).read_text()).items() if k != "timing_ms"})
    assert plans[0] == plans[1]


def test_importing_the_cli_loads_no_simulation_nor_plotting():
    code = ("import sys, contourgrasp, contourgrasp.cli; heavy = ['mujoco', 'trimesh', 'coacd', 'matplotlib', "
            "'contourgrasp.sim', 'contourgrasp.visualize']; print([m for m in heavy if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"


def test_mesh_names_are_distinct_and_never_a_thesis_objects():
    from contourgrasp.cli import _mesh_names

    paths = ["a/YcbMustardBottle/model.obj", "b/YcbGelatinBox/model.obj", "robosuite/bottle.obj", "x/mug.obj"]
    assert _mesh_names(paths) == ["YcbMustardBottle", "YcbGelatinBox", "robosuite-bottle", "mug"]


def test_console_script_has_no_traceback(tmp_path):
    result = subprocess.run([sys.executable, "-m", "contourgrasp.cli", "synth", "--contour", str(tmp_path / "x.csv")],
                            capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip() == f"contourgrasp: error: {tmp_path / 'x.csv'}: contour file not found"


# --- fuzz: random argv from the real options, absurd values and malformed files --------------------------------

ABSURD = ["1e-300", "1e300", "nan", "-inf", "inf", "abc", "", "0", "-1", "9" * 30, "1e309", "--", "-0"]
#: Valid values that keep a plan fast (a coarse grid); absurd ones either fail validation or shrink the grid.
FAST_VALUES = {
    "--xy-step": ["0.05", "0.1", "1e300"], "--yaw-step-deg": ["30", "90", "1e300"], "--d-max": ["0.05", "0.1"],
    "--d-min": ["0", "0.01", "1e-300"], "--harmonics": ["1", "4", "adaptive"], "--clearance": ["0", "1e-300"],
    "--friction": ["0", "0.5", "1e300"], "--quality-gain": ["0", "1e300"], "--top-k": ["1", "3", "9" * 30],
    "--curvature": ["paper", "geometric"], "--planner": ["paper", "default"],
    "--hand": ["three-finger", "five-finger-linear"], "--depth-scale": ["0.001", "1e-300", "1e300"],
    "--standoff": ["0", "0.1", "1e300"], "--approach-offset=": ["0.01", "-1e9", "1e300"],
    "--segment": ["auto", "rgb", "depth"], "--depth-mode": ["max", "plane"],
    "--colour-offset": ["0,0", "1,-3", "99999,99999"], "--max-imbalance": ["0.25", "hand", "9" * 400],
}
SWITCHES = ["--refine", "--no-refine", "--finger-thickness", "--require-closure", "--no-fill-holes", "--footprint"]
FILE_OPTIONS = ["--hand", "--planner"]
IMAGE_OPTIONS = ["--rgb", "--depth", "--intrinsics", "--mask", "--extrinsics"]


@pytest.fixture(scope="module")
def fuzz_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    nested_json = "[" * 100000 + "]" * 100000
    contents = {
        "empty": b"", "random": bytes(range(256)) * 4, "utf16": "x,y\n0,0\n1,0\n0,1\n".encode("utf-16"),
        "json": nested_json.encode(), "yaml": ("a:\n" + "".join(" " * i + "- \n" for i in range(1, 200))).encode(),
        "toml": ("a = " + "[" * 50000 + "]" * 50000 + "\n").encode(),
        "digits": ('{"fx": ' + "9" * 5000 + ', "fy": 500, "cx": 1, "cy": 1, "width": 2, "height": 2}').encode(),
        "bomb": ("a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + "".join(
            f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
            for p, c in zip("abcdefgh", "bcdefghi"))).encode(),
        "bodies": ("<mujoco><worldbody><body name='palm'><geom size='0.01'/>" + "".join(
            f"<body name='b{i}' pos='{0.01 * i} 0 0'><joint/><geom size='0.005'/></body>" for i in range(2000))
            + "</body></worldbody></mujoco>").encode(),
        "dense": _dense_png(),
    }
    files = []
    for stem, data in contents.items():
        for suffix in (".csv", ".npy", ".toml", ".json", ".yaml", ".png", ".obj", ".xml"):
            path = folder / f"{stem}{suffix}"
            path.write_bytes(data)
            files.append(str(path))
    (folder / "adir").mkdir()
    (folder / "journal").mkdir()
    (folder / "journal" / "trials.jsonl").write_bytes(b'{"bench": {"objects": [1, 2]}}\n{}\n[1, 2]\n\xff\xfe\n')
    return folder, files


def _dense_png() -> bytes:
    """A 6000 x 5000 image (30 MP, above the pixels read) in a few kB of PNG."""
    import cv2

    return cv2.imencode(".png", np.zeros((6000, 5000), np.uint8))[1].tobytes()


def _value(option):
    return st.sampled_from(ABSURD + FAST_VALUES.get(option, []))


@st.composite
def argv_strategy(draw, files, folder):
    command = draw(st.sampled_from(["synth", "synth", "efd", "plan", "hands", "bench", "calibrate", "hand-from-model"]))
    any_file = st.sampled_from(files + ["example:can", "example:nope", str(folder / "missing.csv"), "x" * 300])
    argv = [command]
    if command in ("synth", "efd"):
        argv += ["--contour", draw(st.sampled_from(["example:can", "example:stone2"]) | any_file)]
    if command == "plan":
        for option in IMAGE_OPTIONS[:3] + draw(st.lists(st.sampled_from(IMAGE_OPTIONS[3:]), max_size=2)):
            argv += [option, draw(any_file)]
    if command == "bench":  # never runs a trial: a malformed mesh, an unknown planner or a bad journal stops it first
        argv += ["--mesh", draw(any_file), "--planners", draw(st.sampled_from(["nope", ""])), "--trials", "1"]
        argv += draw(st.sampled_from([[], ["--workers", "1000"], ["--ray", "[::1"], ["--ray", "ray://:5"],
                                      ["--resume", str(folder)], ["--resume", str(folder / "journal")]]))
    if command == "plan" and draw(st.booleans()):  # a bag instead of the files
        argv = ["plan", "--bag", draw(any_file | st.just(str(folder))), "--color-topic", "/c", "--depth-topic", "/d",
                "--info-topic", "/i", "--bag-index", draw(st.sampled_from(["0", "9" * 30]))]
    if command == "calibrate":  # never simulates: every hand here is malformed or refused
        argv += ["--hand", draw(any_file | st.just("five-finger-curved-thumb"))]
    if command == "hand-from-model":  # never simulates: every model here is malformed or missing
        argv += [draw(any_file), "--fingertips", "tip", *draw(st.sampled_from([[], ["--palm", "palm"]]))]
    if command in ("synth", "plan"):
        argv += ["--yaw-step-deg", draw(_value("--yaw-step-deg"))]  # bounds the grid unless the value is refused
        for option in draw(st.lists(st.sampled_from(sorted(FAST_VALUES) + SWITCHES + FILE_OPTIONS), max_size=6)):
            if option in SWITCHES:
                argv.append(option)
            elif option.endswith("="):
                argv.append(option + draw(_value(option)))
            else:
                argv += [option, draw(_value(option) | any_file if option in FILE_OPTIONS else _value(option))]
    if command == "efd":
        argv += ["--harmonics", *draw(st.lists(_value("--harmonics"), min_size=1, max_size=3))]
    if command in ("synth", "plan", "efd", "calibrate") and draw(st.booleans()) or command == "hand-from-model":
        own_inputs = [a for a in argv if a in files]  # an output naming an input must be refused
        targets = st.sampled_from([str(folder / "out.json"), str(folder / "adir"), str(folder / "no" / "x.json"),
                                   *own_inputs])
        argv += [draw(st.sampled_from(["--out"] if command == "hand-from-model" else ["--out", "--plot"])), draw(targets)]
    return argv


def test_fuzz_the_command_line_never_tracebacks(fuzz_files):
    folder, files = fuzz_files
    before = {p: Path(p).read_bytes() for p in files}

    @settings(max_examples=100, deadline=None, suppress_health_check=list(HealthCheck))
    @given(argv=argv_strategy(files, folder))
    def check(argv):
        err, out = io.StringIO(), io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            code = main(argv)
        text = err.getvalue()
        assert code in (0, 2, 3), (argv, text)
        assert "Traceback" not in text and len(text.strip().splitlines()) <= 4, (argv, text)
        assert all(len(line) < 2000 for line in text.splitlines()), argv

    check()
    assert {p: Path(p).read_bytes() for p in files} == before  # no input was ever overwritten


# --- hand-from-model ---

@pytest.mark.parametrize("model", ["inspire", "jaco-three-finger", "mpl"])
def test_hand_from_model_writes_a_hand_that_plans(tmp_path, capsys, model):
    hand = tmp_path / "hand.toml"
    code, out, err = run(capsys, "hand-from-model", model, "--out", hand)
    assert code == 0, err
    assert "fit error mm" in out and f"hand -> {hand}" in out
    code, out, err = run(capsys, "synth", "--contour", "example:can", "--hand", hand, *FAST, "--out",
                         tmp_path / "plan.json")
    assert code == 0, err
    assert json.loads((tmp_path / "plan.json").read_text())["hand"] == model
    brushing = "tips_brush_table = true" in hand.read_text()
    assert brushing == (model == "inspire")  # the bundled models' own, chosen on the bench
    assert ("grasp_height_fraction = 0.0" in hand.read_text()) == (model == "inspire")
    assert ("slice_contour = false" in hand.read_text()) == (model == "inspire")
    code, _, err = run(capsys, "hand-from-model", model, "--out", hand, "--no-tips-brush-table",
                       "--grasp-height-fraction", "0.3", "--slice-contour", "true")
    assert code == 0 and "tips_brush_table = false" in hand.read_text(), err
    assert "grasp_height_fraction = 0.3" in hand.read_text() and "slice_contour = true" in hand.read_text()


def test_hand_from_model_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys):
    model = Path(__file__).parent / "handmodels" / "fixtures" / "two-sliders.xml"
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><body></mujoco>")
    out = tmp_path / "hand.toml"
    cases = [
        ([model, "--fingertips", "left_tip", "thumb_tip"], "no site or body named 'thumb_tip'"),
        ([model, "--fingertips", "left_tip", "right_tip", "--actuators", "right_drive"],
         "fingertip 'left_tip' does not move"),
        ([model, "--fingertips", "left_tip", "right_tip", "--palm", "plate"], "palm 'plate' is not a body (a geom)"),
        ([broken, "--fingertips", "tip"], "broken.xml: cannot load the MuJoCo model"),
        ([tmp_path / "missing.xml", "--fingertips", "tip"], "no such model file"),
        ([model, "--fingertips", "left_tip", "right_tip", "--grasp-height-fraction", "0.9"],
         "grasp_height_fraction must be at most 0.7"),
        ([model, "--fingertips", "left_tip", "right_tip", "--slice-contour", "sometimes"],
         "argument --slice-contour: invalid choice: 'sometimes'"),
    ]
    for argv, message in cases:
        code, _, err = run(capsys, "hand-from-model", *argv, "--out", out)
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
        assert not out.exists()


def test_bench_on_a_hand_model_runs_and_refuses_mixed_options(tmp_path, capsys):
    code, out, err = run(capsys, "bench", "--hand-model", "jaco-three-finger", "--objects", "can", "--trials", "1",
                         "--planners", "default", "--workers", "1", "--out", tmp_path / "bench")
    assert code == 0, err
    assert "| default |" in out and (tmp_path / "bench" / "trials.json").exists()
    for argv, message in [(["--hand-model", "inspire", "--hand", "three-finger"], "give --hand or --hand-model"),
                          (["--fingertips", "tip"], "--fingertips needs --hand-model")]:
        code, _, err = run(capsys, "bench", *argv, "--objects", "can", "--trials", "1", "--out", tmp_path / "other")
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / "other").exists()


def test_the_help_gives_the_options_own_defaults(capsys):
    """The flags default to None (the planner's value, else the option's); their help quotes the option's default,
    written out so that ``--help`` does not import the pipeline."""
    from contourgrasp.pipeline import PlanOptions

    defaults = PlanOptions()
    assert main(["plan", "--help"]) == 0
    shown = " ".join(capsys.readouterr().out.split())
    assert f"(default {defaults.perception.approach_offset:g})" in shown
    assert f"pre-grasp distance, m (default {defaults.standoff:g})" in shown
    assert f"(default {defaults.search.top_k})" in shown and f"(default {defaults.perception.segment})" in shown


@pytest.mark.parametrize("argv, extra", [
    (["bench", "--objects", "can", "--trials", "1"], "sim"),
    (["hand-from-model", "inspire", "--out", "hand.toml"], "sim"),
    (["calibrate"], "sim"),
])
def test_a_command_whose_extra_is_missing_names_it_in_one_line(tmp_path, argv, extra):
    """Without the [sim] extra (MuJoCo made unimportable in a fresh interpreter) planning still works and the
    simulation's commands say which extra to install."""
    code = ("import sys; sys.modules['mujoco'] = None\n"
            "from contourgrasp.cli import main\n"
            f"assert main(['synth', '--contour', 'example:can', '--hand', 'three-finger', '--yaw-step-deg', '30',"
            f" '--out', {str(tmp_path / 'plan.json')!r}]) == 0\n"
            f"sys.exit(main({argv!r}))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().splitlines()[-1] == (f"contourgrasp: error: {argv[0]} needs mujoco, which is not "
                                                    f"installed: pip install 'contourgrasp[{extra}]'")
    assert (tmp_path / "plan.json").is_file() and not (tmp_path / "hand.toml").exists()


def test_bench_help_names_every_sensor_preset_and_its_default(capsys):
    from contourgrasp.sim import DEFAULT_SENSOR, SENSORS

    assert main(["bench", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    sensor = text[text.rindex("--sensor SENSOR"):text.rindex("--tilt DEG")]  # the option, not the usage line
    assert all(name in sensor for name in SENSORS) and f"(default: {DEFAULT_SENSOR})" in sensor



def test_a_bench_prints_no_trials_perception_warnings(tmp_path, capsys):
    argv = ["bench", "--objects", "can", "--trials", "2", "--planners", "default", "--tilt", "45", "--workers", "1",
            "--out", str(tmp_path / "b")]
    assert main(argv) == 0
    assert "warning" not in capsys.readouterr().err  # each would say the camera is tilted 45 deg


def test_bench_clear_protocol_needs_a_scene_of_several_objects(tmp_path, capsys):
    code, out, err = run(capsys, "bench", "--protocol", "clear", "--objects", "can", "--out", tmp_path / "b")
    assert code == 2 and err.startswith("contourgrasp: error: protocol 'clear' needs a scene of several objects")
    assert not (tmp_path / "b").exists()

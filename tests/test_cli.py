import json
import subprocess
import sys

import numpy as np
import pytest

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
    code, out, err = run(capsys, "synth", "--contour", "example:case", "--hand", "three-finger", *FAST,
                         "--out", out_json, "--plot", out_png, "--top-k", "4", "--d-max", "0.1", "0.12")
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
    with pytest.raises(SystemExit) as exc:
        main(["synth", "--contour", "example:can", "--xy-step", "-1"])
    assert exc.value.code == 2


def test_console_script_has_no_traceback(tmp_path):
    result = subprocess.run([sys.executable, "-m", "contourgrasp.cli", "synth", "--contour", str(tmp_path / "x.csv")],
                            capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip() == f"contourgrasp: error: {tmp_path / 'x.csv'}: contour file not found"

"""The example scripts run as a user runs them (a fresh python3, PYTHONPATH as the README
says) at a tiny resolution, and write PNG figures matplotlib reads back."""
import subprocess
import sys

import matplotlib.image

from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples"


def run_example(script, *args):
    proc = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def check_png(path):
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    img = matplotlib.image.imread(str(path))
    assert img.shape[0] > 100 and img.shape[1] > 100
    assert img.std() > 0, "a figure is not one flat colour"


def test_methods_side_by_side(tmp_path):
    out = tmp_path / "methods.png"
    run_example("methods_side_by_side.py", "--resolution", "24x20", "--spp", "1", "--reference-spp", "4",
                "--out", out)
    check_png(out)


def test_convergence(tmp_path):
    out = tmp_path / "convergence.png"
    run_example("convergence.py", "--resolution", "16x12", "--spp", "1,2", "--reference-spp", "4", "--out", out)
    check_png(out)


def test_layers_crops(tmp_path):
    out = tmp_path / "crops.png"
    run_example("layers_crops.py", "--scale", "0.125", "--spp", "2", "--reference-spp", "4", "--zoom", "8", "--out", out)
    check_png(out)


def test_layers_crops_of_two_moving_layers_crossing(tmp_path):
    out = tmp_path / "order.png"
    run_example("layers_crops.py", "--set", "order", "--scale", "0.125", "--spp", "2", "--reference-spp", "4", "--zoom", "8",
                "--out", out)
    check_png(out)


def test_layers_crops_of_the_floor_beside_a_box_coming_closer(tmp_path):
    out = tmp_path / "sliver.png"
    run_example("layers_crops.py", "--set", "sliver", "--scale", "0.125", "--spp", "2", "--reference-spp", "4", "--zoom", "8",
                "--out", out)
    check_png(out)


def test_layers_crops_of_a_moving_and_turning_camera(tmp_path):
    out = tmp_path / "camera.png"
    run_example("layers_crops.py", "--set", "camera", "--scale", "0.125", "--spp", "2", "--reference-spp", "4", "--zoom", "8",
                "--out", out)
    check_png(out)

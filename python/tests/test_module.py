"""The module's surface: a render's shapes, dtypes and stats, its buffers, the scene list,
load_scene(dict) against the same JSON file, and the thread count leaving the image alone."""
import json

import numpy as np
import pytest

import wedge
from conftest import RESOLUTION, SCENE, SEED, SPP, SOURCE_DIR, run_cli


def render(scene, **kw):
    args = dict(method="maaf", spp=SPP, seed=SEED, resolution=RESOLUTION, quiet=True)
    args.update(kw)
    return wedge.render(scene, **args)


def test_scenes_are_the_cli_list():
    listed = [line.split()[0] for line in run_cli("scenes").stdout.splitlines() if line and not line[0].isspace()]
    assert wedge.scenes() == listed
    assert "cornell" in wedge.scenes()


def test_color_shape_dtype_and_values(cornell):
    r = render(cornell)
    w, h = RESOLUTION
    assert r.color.shape == (h, w, 3)
    assert r.color.dtype == np.float32
    assert np.all(np.isfinite(r.color))
    assert r.color.max() > 0, "a lit Cornell box is not black"
    assert not r.color.flags.writeable, "the arrays are views of the render: read-only"


def test_buffers_are_named_planes(cornell):
    r = render(cornell)
    w, h = RESOLUTION
    b = r.buffers
    for name in ("depth", "spp", "normal.X", "coverage", "object"):
        assert name in b, sorted(b)
    assert not {"R", "G", "B"} & set(b), "R, G, B are .color"
    for name, plane in b.items():
        assert plane.shape == (h, w), name
        assert plane.dtype == np.float32, name
    # The spp plane counts whole samples, and its mean is the stats' average.
    spp = b["spp"]
    assert np.all(spp == np.round(spp)) and spp.min() >= SPP
    assert spp.mean(dtype=np.float64) == pytest.approx(r.stats["spp_average"], rel=1e-6)


def test_stats_have_the_cli_keys(cornell, tmp_path):
    r = render(cornell)
    stats_file = tmp_path / "stats.json"
    w, h = RESOLUTION
    run_cli("render", SCENE, "--method", "maaf", "--spp", SPP, "--seed", SEED, "--resolution", f"{w}x{h}",
            "--quiet", "--stats", stats_file)
    cli = json.loads(stats_file.read_text())
    assert set(r.stats) == set(cli)
    assert set(r.stats["seconds"]) == set(cli["seconds"])
    for key in ("scene", "method", "resolution", "spp_average", "rays"):
        assert r.stats[key] == cli[key], key
    assert r.stats["resolution"] == [w, h]


def test_same_image_whatever_the_thread_count(cornell):
    one = render(cornell, threads=1)
    two = render(cornell, threads=2)
    assert np.array_equal(one.color, two.color)


def test_keywords_reach_the_options(cornell):
    # spp is mc's sample count (plus the top-ups of pixels that see an emitter or several
    # surfaces): more samples, a higher average and another image.
    a = render(cornell, method="mc", spp=1)
    b = render(cornell, method="mc", spp=3)
    assert 1 <= a.stats["spp_average"] < b.stats["spp_average"]
    assert np.all(a.buffers["spp"] >= 1) and np.all(b.buffers["spp"] >= 3)
    assert not np.array_equal(a.color, b.color)
    # A negated flag: no_variance=True is --no-variance, which changes à-trous' edge-stopping.
    guided = render(cornell, method="atrous")
    plain = render(cornell, method="atrous", no_variance=True)
    assert not np.array_equal(guided.color, plain.color)
    assert np.array_equal(guided.color, render(cornell, method="atrous", no_variance=False).color)
    # An option with values: layers="on"|"off"|"auto"; True and False are "on" and "off".
    layered = render(cornell, method="mc", layers="on")
    plain = render(cornell, method="mc", layers="off")
    assert not np.array_equal(layered.color, plain.color)
    assert np.array_equal(render(cornell, method="mc", layers=True).color, layered.color)
    assert np.array_equal(render(cornell, method="mc", layers=False).color, plain.color)


def test_load_scene_dict_equals_the_file(monkeypatch):
    path = SOURCE_DIR / "scenes" / "cornell" / "cornell.json"
    from_file = wedge.load_scene(str(path))
    # The dict's relative mesh path resolves against the current directory.
    monkeypatch.chdir(path.parent)
    from_dict = wedge.load_scene(json.loads(path.read_text()))
    assert from_dict.resolution == from_file.resolution
    a, b = render(from_file), render(from_dict)
    assert np.array_equal(a.color, b.color)
    for name in a.buffers:
        assert np.array_equal(a.buffers[name], b.buffers[name]), name


def test_a_light_facing_away_from_everything_warns():
    # A parallelogram emits towards edge1 x edge2: swapped, the light above a quad emits
    # upwards, away from it, and the render is black and warns as `wedge render` does.
    scene = {
        "camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [8, 8]},
        "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
        "lights": [{"type": "parallelogram", "corner": [-0.5, 2, -0.5], "edge1": [0, 0, 1], "edge2": [1, 0, 0],
                    "radiance": [5, 5, 5]}],
        "objects": [{"type": "quad", "corner": [-2, 0, 2], "edge1": [4, 0, 0], "edge2": [0, 0, -4], "material": "white"}],
    }
    with pytest.warns(UserWarning, match="no light reached any surface"):
        r = render(wedge.load_scene(scene), method="mc")
    assert r.stats["lit_samples"] == 0 and not np.any(r.color)
    scene["lights"][0]["edge1"], scene["lights"][0]["edge2"] = [1, 0, 0], [0, 0, 1]
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = render(wedge.load_scene(scene), method="mc")
    assert r.stats["lit_samples"] > 0 and np.all(r.color.mean(axis=(0, 1)) > 0)


def test_load_scene_takes_a_path_object():
    path = SOURCE_DIR / "scenes" / "cornell" / "cornell.json"
    assert wedge.load_scene(path).resolution == wedge.load_scene("cornell").resolution


def test_write_image_formats(cornell, tmp_path):
    r = render(cornell)
    for ext in ("exr", "png", "pfm"):
        wedge.write_image(str(tmp_path / f"x.{ext}"), r)
        assert (tmp_path / f"x.{ext}").stat().st_size > 0
    # An array writes as its colour: the PFM holds exactly r.color.
    from conftest import read_pfm
    wedge.write_image(str(tmp_path / "a.pfm"), np.array(r.color))
    assert np.array_equal(read_pfm(tmp_path / "a.pfm"), r.color)


def test_error_is_a_value_error():
    assert issubclass(wedge.Error, ValueError)


def test_the_gil_is_released_while_rendering(cornell):
    # A Python thread that notes the time every millisecond: with the GIL held for the whole
    # render it could note nothing between the render's start and end.
    import threading
    import time
    ticks, stop = [], threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    try:
        start = time.perf_counter()
        wedge.render(cornell, method="mc", spp=64, resolution=(128, 128), quiet=True)
        end = time.perf_counter()
    finally:
        stop.set()
        t.join()
    assert sum(start < x < end for x in ticks) >= 2

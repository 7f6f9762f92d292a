"""The module against the command line: the same render gives the CLI's image bit for bit (the
colour through PFM, every buffer through the EXR file's bytes), compare() gives what
`wedge compare --json` prints, and every bad input raises wedge.Error with the CLI's message."""
import json

import numpy as np
import pytest

import wedge
from conftest import RESOLUTION, SCENE, SEED, SPP, cli_error, read_pfm, run_cli

SIZE = f"{RESOLUTION[0]}x{RESOLUTION[1]}"


@pytest.mark.parametrize("method", ["mc", "aaf", "maaf", "atrous"])
def test_render_equals_the_cli_bit_for_bit(cornell, tmp_path, method):
    cli_exr, cli_pfm, cli_png = tmp_path / "cli.exr", tmp_path / "cli.pfm", tmp_path / "cli.png"
    run_cli("render", SCENE, "--method", method, "--spp", SPP, "--seed", SEED, "--resolution", SIZE, "--quiet",
            "-o", cli_exr, "-o", cli_pfm, "-o", cli_png)
    r = wedge.render(cornell, method=method, spp=SPP, seed=SEED, resolution=RESOLUTION, threads=2, quiet=True)
    assert np.array_equal(r.color, read_pfm(cli_pfm))
    py_exr, py_png = tmp_path / "py.exr", tmp_path / "py.png"
    wedge.write_image(str(py_exr), r)
    wedge.write_image(str(py_png), r)
    assert py_exr.read_bytes() == cli_exr.read_bytes()
    assert py_png.read_bytes() == cli_png.read_bytes()


def test_compare_equals_the_cli_json(cornell, tmp_path):
    kw = dict(spp=SPP, seed=SEED, resolution=RESOLUTION, quiet=True)
    test = wedge.render(cornell, method="aaf", **kw)
    ref = wedge.render(cornell, method="mc", **{**kw, "spp": 16, "seed": SEED + 1})
    wedge.write_image(str(tmp_path / "test.exr"), test)
    wedge.write_image(str(tmp_path / "ref.exr"), ref)
    cli = json.loads(run_cli("compare", tmp_path / "test.exr", tmp_path / "ref.exr", "--json").stdout)
    for got in (wedge.compare(test, ref), wedge.compare(np.array(test.color), ref.color),
                wedge.compare(str(tmp_path / "test.exr"), tmp_path / "ref.exr")):
        assert got == {k: cli[k] for k in ("relmse", "smape", "psnr", "ssim")}
    assert got["relmse"] > 0
    # Identical images: PSNR is infinite, None as the CLI's null.
    same = json.loads(run_cli("compare", tmp_path / "ref.exr", tmp_path / "ref.exr", "--json").stdout)
    assert same["psnr"] is None and wedge.compare(ref, ref)["psnr"] is None
    assert wedge.compare(ref, ref)["relmse"] == 0


def test_compare_splits_the_error_as_the_cli_does(cornell, tmp_path):
    # variance_from and reference_noise_from give what --variance-from and --reference-noise-from
    # print: the variance, the reference's own noise, the net relMSE and the squared bias.
    kw = dict(spp=SPP, resolution=RESOLUTION, quiet=True)
    images = {"a": wedge.render(cornell, method="mc", seed=1, **kw),
              "b": wedge.render(cornell, method="mc", seed=2, **kw),
              "r1": wedge.render(cornell, method="mc", seed=3, **{**kw, "spp": 16}),
              "r2": wedge.render(cornell, method="mc", seed=4, **{**kw, "spp": 16})}
    for name, r in images.items():
        wedge.write_image(str(tmp_path / f"{name}.exr"), r)
    path = {name: str(tmp_path / f"{name}.exr") for name in images}
    cli = json.loads(run_cli("compare", path["a"], path["r1"], "--json", "--variance-from", path["b"],
                             "--reference-noise-from", path["r2"]).stdout)
    got = wedge.compare(images["a"], images["r1"], variance_from=images["b"], reference_noise_from=path["r2"])
    keys = ("relmse", "variance", "bias2_and_reference_noise", "reference_noise", "relmse_net", "bias2")
    assert {k: got[k] for k in keys} == pytest.approx({k: cli[k] for k in keys}, rel=1e-12, abs=1e-15)
    assert got["reference_noise"] > 0 and got["relmse_net"] == pytest.approx(got["relmse"] - got["reference_noise"])
    # Either alone adds only its own keys; a second image of another size is the CLI's error.
    assert "variance" not in wedge.compare(images["a"], images["r1"], reference_noise_from=images["r2"])
    assert "reference_noise" not in wedge.compare(images["a"], images["r1"], variance_from=images["b"])
    small = tmp_path / "small.pfm"
    wedge.write_image(str(small), np.ones((4, 4, 3), np.float32))
    for keyword, flag in (("variance_from", "--variance-from"), ("reference_noise_from", "--reference-noise-from")):
        message = error_of(wedge.compare, path["a"], path["r1"], **{keyword: str(small)})
        assert message == cli_error("compare", path["a"], path["r1"], flag, small)
        assert message.startswith(f"{small}: {flag}: image size 4x4 differs from")


def test_read_image_and_buffers_give_back_what_was_written(cornell, tmp_path):
    # read_image() reads what `wedge compare` reads; read_buffers() an EXR's named planes.
    r = wedge.render(cornell, method="aaf", spp=SPP, seed=SEED, resolution=RESOLUTION, quiet=True)
    for ext in ("exr", "pfm", "png"):
        wedge.write_image(str(tmp_path / f"x.{ext}"), r)
    assert np.array_equal(wedge.read_image(tmp_path / "x.exr"), r.color)
    assert np.array_equal(wedge.read_image(str(tmp_path / "x.pfm")), r.color)
    png = wedge.read_image(tmp_path / "x.png")  # 8-bit sRGB decoded: what compare() measures of the file
    assert png.shape == r.color.shape and png.dtype == np.float32
    assert wedge.compare(png, r) == wedge.compare(str(tmp_path / "x.png"), r)
    planes = wedge.read_buffers(tmp_path / "x.exr")
    assert planes.keys() == r.buffers.keys() and "depth" in planes
    assert all(np.array_equal(planes[k], r.buffers[k]) for k in planes)
    # Bad input names the file, as the CLI does.
    missing = tmp_path / "missing.exr"
    assert error_of(wedge.read_image, missing) == cli_error("compare", missing, tmp_path / "x.exr")
    message = error_of(wedge.read_buffers, tmp_path / "x.pfm")
    assert message.startswith(f"{tmp_path / 'x.pfm'}: read_buffers() needs an EXR")


def error_of(call, *args, **kwargs):
    with pytest.raises(wedge.Error) as e:
        call(*args, **kwargs)
    return str(e.value)


# (render keywords, the same flags for `wedge render cornell`)
BAD_OPTIONS = [
    (dict(spp=0), ["--spp", "0"]),
    (dict(spp="many"), ["--spp", "many"]),
    (dict(seed=-1), ["--seed=-1"]),
    (dict(method="magic"), ["--method", "magic"]),
    (dict(threads=5000), ["--threads", "5000"]),
    (dict(resolution=(0, 16)), ["--resolution", "0x16"]),
    (dict(resolution="24by16"), ["--resolution", "24by16"]),
    (dict(max_extra_spp=-3), ["--max-extra-spp=-3"]),
    (dict(maaf_components=4), ["--maaf-components", "4"]),
    (dict(maaf_weights="flat"), ["--maaf-weights", "flat"]),
    (dict(sigma_color=float("nan")), ["--sigma-color", "nan"]),
    (dict(aov="/nonexistent/dir"), ["--aov", "/nonexistent/dir"]),
    (dict(layers="sometimes"), ["--layers", "sometimes"]),
    (dict(sampler="halton"), ["--sampler", "halton"]),
    (dict(no_such_option=1), ["--no-such-option=1"]),
]


@pytest.mark.parametrize("kwargs,flags", BAD_OPTIONS, ids=[f[0] for _, f in BAD_OPTIONS])
def test_bad_options_raise_the_cli_message(cornell, kwargs, flags):
    message = error_of(wedge.render, cornell, quiet=True, **kwargs)
    assert message == cli_error("render", SCENE, *flags)
    assert message  # names the flag: never an empty message


def test_bad_scenes_raise_the_cli_message(tmp_path):
    assert error_of(wedge.load_scene, "no-such-scene") == cli_error("render", "no-such-scene")
    bad = {"camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": -40,
                      "resolution": [8, 8]},
           "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    cli = cli_error("render", path)
    assert error_of(wedge.load_scene, str(path)) == cli
    # The dict's message is the file's, with "<dict>" where the file's name was.
    assert error_of(wedge.load_scene, bad) == cli.replace(str(path), "<dict>")
    assert "fov_y" in cli


def test_bad_outputs_and_images_raise_the_cli_message(cornell, tmp_path):
    r = wedge.render(cornell, spp=1, resolution=(8, 6), quiet=True)
    assert error_of(wedge.write_image, str(tmp_path / "x.tiff"), r) == \
        cli_error("render", SCENE, "--spp", "1", "--resolution", "8x6", "-q", "-o", tmp_path / "x.tiff")
    missing = str(tmp_path / "no-dir" / "x.png")
    assert error_of(wedge.write_image, missing, r) == \
        cli_error("render", SCENE, "--spp", "1", "--resolution", "8x6", "-q", "-o", missing)
    # Sizes that differ, and a non-finite pixel, as `wedge compare` reports them for files.
    small, big = tmp_path / "small.pfm", tmp_path / "big.pfm"
    wedge.write_image(str(small), r)
    wedge.write_image(str(big), np.ones((7, 9, 3), np.float32))
    assert error_of(wedge.compare, str(small), str(big)) == cli_error("compare", small, big)
    nan = np.ones((6, 8, 3), np.float32)
    nan[2, 3, 1] = np.nan
    wedge.write_image(str(tmp_path / "nan.pfm"), nan)
    assert error_of(wedge.compare, str(tmp_path / "nan.pfm"), str(small)) == \
        cli_error("compare", tmp_path / "nan.pfm", small)
    # Arrays have no file name: the message names them test and reference.
    assert error_of(wedge.compare, nan, r).startswith("test: 1 of 48 pixels are not finite")
    assert "expected a float array of shape (H, W, 3)" in error_of(wedge.compare, np.ones((4, 4)), r)
    assert error_of(wedge.compare, str(tmp_path / "missing.exr"), r) == \
        cli_error("compare", tmp_path / "missing.exr", small)

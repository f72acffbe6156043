"""The command ``mitsuba-birefringent`` (plugin/mitsuba_birefringent/cli.py): it renders every XML
scene of scenes/ to EXR, and its options mean what they mean for Mitsuba 3.9.1's ``mitsuba``
(which itself cannot render these scenes). Each case runs the installed console script in a
subprocess, as a user would.
"""

from __future__ import annotations

import importlib
import pathlib
import re
import shutil
import subprocess
import sys

import mitsuba as mi
import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
BIN = pathlib.Path(sys.executable).parent
COMMAND = BIN / "mitsuba-birefringent"
sys.path.insert(0, str(SCENES))

#: Width of the test renders (the height keeps the scene's aspect).
WIDTH = 32


def run(*args: str, cwd: pathlib.Path = ROOT, timeout: float = 300) -> subprocess.CompletedProcess:
    if not COMMAND.exists():
        pytest.fail(f"{COMMAND} does not exist: run make setup (it installs the package)")
    return subprocess.run([str(COMMAND), *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)


def small_size(xml: pathlib.Path) -> list[str]:
    """`-D` options for a WIDTH-wide render with the scene's aspect, and 2 samples per pixel."""
    defaults = dict(re.findall(r'<default name="(\w+)" value="([^"]*)"/>', xml.read_text()))
    out = ["-D", "spp=2"] if "spp" in defaults else []
    if "width" in defaults and "height" in defaults:
        height = max(1, round(WIDTH * int(defaults["height"]) / int(defaults["width"])))
        out += ["-D", f"width={WIDTH}", "-D", f"height={height}"]
    return out


def read_exr(path: pathlib.Path) -> np.ndarray:
    mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(str(path)))


@pytest.mark.parametrize("xml", sorted(SCENES.glob("*.xml")), ids=lambda p: p.stem)
def test_every_xml_scene_renders_to_exr(xml, tmp_path):
    module = importlib.import_module(xml.stem)
    if hasattr(module, "write_data"):  # the textures the XML reads from scenes/data/
        mi.set_variant(module.VARIANTS[0])
        module.write_data()
    out = tmp_path / f"{xml.stem}.exr"
    result = run("-m", module.VARIANTS[0], *small_size(xml), "-o", str(out), str(xml))
    assert result.returncode == 0, result.stderr + result.stdout
    image = read_exr(out)
    assert image.shape[1] == WIDTH, image.shape
    assert np.isfinite(image).all()
    assert image[..., :3].mean() > 0, "a black image"


@pytest.mark.parametrize("threads", [2, 7])
def test_options_reach_the_render(tmp_path, threads):
    # -t, --spp and -m as Mitsuba's own log reports them (-t N: N - 1 workers and the calling
    # thread); -D sets the size of the output file. The file is written although the pool was
    # resized: -t 2 shrinks it on a machine with more than one core, after which Mitsuba's EXR
    # writer would deadlock (measured: it hangs without the restore in cli.thread_count).
    xml = SCENES / "waveplates.xml"
    out = tmp_path / "out.exr"
    result = run("-m", "scalar_spectral_polarized", "-t", str(threads), "--spp", "3", "-D",
                 "width=20", "-D", "height=7", "-o", str(out), str(xml), timeout=60)
    assert result.returncode == 0, result.stderr + result.stdout
    log = result.stdout + result.stderr
    assert '"scalar_spectral_polarized" variant' in log
    assert f"(20x7, 3 samples, {threads} threads)" in log, log
    assert read_exr(out).shape[:2] == (7, 20)


def test_search_path_and_default_output(tmp_path):
    # A copy of a scene outside scenes/ finds its textures (data/...) only through -a, and
    # without -o the image is written beside the scene with the film's extension.
    mi.set_variant("scalar_spectral_polarized")
    importlib.import_module("photoelastic_disk").write_data()
    xml = tmp_path / "disk.xml"
    shutil.copy(SCENES / "photoelastic_disk.xml", xml)
    size = ["-D", "width=8", "-D", "height=8", "-D", "spp=1"]
    missing = run("-m", "scalar_spectral_polarized", *size, str(xml), cwd=tmp_path)
    assert missing.returncode == 1, missing.stdout
    assert re.search(r'"data/photoelastic_disk_\w+\.exr": I/O error', missing.stderr), missing.stderr
    found = run("-m", "scalar_spectral_polarized", *size, "-a", f"{tmp_path};{SCENES}", str(xml),
                cwd=tmp_path)
    assert found.returncode == 0, found.stderr + found.stdout
    assert (tmp_path / "disk.exr").is_file()


def test_output_is_written_in_the_format_its_extension_names(tmp_path):
    """`-o` writes what it names (Mitsuba's `mitsuba` writes its film's EXR whatever the
    extension): the EXR of the film, and, from the same render (seed 0), its RGB channels as
    8-bit sRGB in PNG (what mi.util.convert_to_bitmap makes of them, pixel for pixel) and in
    floating point in .pfm (the EXR's values as the film stores them, half floats)."""
    xml = SCENES / "waveplates.xml"
    size = ["-m", "scalar_spectral_polarized", "-D", "width=12", "-D", "height=5", "--spp", "2"]
    for name in ("out.exr", "out.png", "out.pfm"):
        result = run(*size, "-o", str(tmp_path / name), str(xml))
        assert result.returncode == 0, result.stderr + result.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.exr", "out.pfm", "out.png"]
    mi.set_variant("scalar_rgb")
    exr = dict(mi.Bitmap(str(tmp_path / "out.exr")).split())["<root>"]
    png = mi.Bitmap(str(tmp_path / "out.png"))
    assert png.component_format() == mi.Struct.Type.UInt8 and png.srgb_gamma()
    want = np.array(mi.util.convert_to_bitmap(np.array(exr)))
    assert np.array(want).mean() > 10, "a black image"
    assert np.abs(np.array(png).astype(int) - want.astype(int)).max() <= 1
    pfm = np.array(mi.Bitmap(str(tmp_path / "out.pfm")))
    np.testing.assert_allclose(pfm, np.array(exr, dtype=np.float32), rtol=1e-3, atol=1e-4)
    refused = run(*size, "-o", str(tmp_path / "out.tiff"), str(xml))
    assert refused.returncode == 1 and "-o" in refused.stderr and ".png" in refused.stderr
    assert not (tmp_path / "out.tiff").exists() and not (tmp_path / "out.exr.tiff").exists()


@pytest.mark.parametrize("args, message", [
    (["-D", "width"], "expected key=value"),
    (["-s", "1"], "sensor index 1 is out of bounds"),
    (["-W"], "only make sense in a JIT"),
    (["-m", "scalar_mono"], "unknown variant 'scalar_mono'"),
    (["--spp", "0"], "--spp must be at least 1"),
])
def test_bad_options_are_clear_errors(args, message):
    result = run("-m", "scalar_spectral_polarized", *args, str(SCENES / "waveplates.xml"))
    assert result.returncode == 1
    assert message in result.stderr, result.stderr


def test_mitsubas_own_command_cannot_load_the_plugins():
    # What README.md says: `mitsuba` knows only the plugins in its wheel.
    mitsuba = BIN / "mitsuba"
    result = subprocess.run([str(mitsuba), "-m", "scalar_spectral_polarized", "-D", "width=8",
                             "-D", "height=8", str(SCENES / "waveplates.xml")],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode != 0
    assert 'Plugin "thinbirefringent" not found' in result.stdout + result.stderr

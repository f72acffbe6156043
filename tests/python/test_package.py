"""The distribution (pyproject.toml, build_backend/): the wheel `pip wheel .` builds installs into
a fresh virtualenv that holds only `mitsuba` from the index, and renders there outside the
repository exactly what the repository's own build renders; its tag, pins and RUNPATH are the
ones docs/building.md §4 states; the version has one source.

The wheel test takes about a minute (pip's isolated build environment, a virtualenv, the
`mitsuba` wheel from pip's cache or the index).
"""

from __future__ import annotations

import json
import os
import pathlib
import re
import subprocess
import sys
import sysconfig
import tomllib
import zipfile

import mitsuba as mi
import numpy as np
import pytest

import mitsuba_birefringent

ROOT = pathlib.Path(__file__).resolve().parents[2]
PIP = ["-m", "pip", "--disable-pip-version-check", "--no-input"]

# A small scene with both plugins, rendered in both environments (the same source text): a
# quartz plate in front of an area light, and a calcite sphere behind the plate.
SCENE = '''
def scene():
    import mitsuba as mi
    T = mi.ScalarTransform4f
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 6},
        "sensor": {"type": "perspective", "fov": 40,
                   "to_world": T().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": 12, "height": 8, "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": 4}},
        "light": {"type": "rectangle", "to_world": T().translate([0, 0, -3]).scale(6),
                  "emitter": {"type": "area", "radiance": {"type": "d65"}}},
        "plate": {"type": "rectangle", "to_world": T().translate([0, 0, 1]).scale(3),
                  "bsdf": {"type": "thinbirefringent", "material": "quartz", "thickness": 20.0,
                           "optic_axis": [1, 1, 0]}},
        "crystal": {"type": "sphere", "radius": 0.6,
                    "bsdf": {"type": "birefringent", "material": "calcite",
                             "optic_axis": [0, 1, 1], "optic_axis_space": "world"}},
    }
'''

# Run by the fresh virtualenv's interpreter, from a temporary directory.
CHECK = SCENE + '''
import json, pathlib, sys
root = pathlib.Path(sys.argv[1]).resolve()
on_path = [p for p in sys.path if p and pathlib.Path(p).resolve().is_relative_to(root)]
assert not on_path, f"repository paths on sys.path: {on_path}"
import mitsuba as mi
import mitsuba_birefringent
package = pathlib.Path(mitsuba_birefringent.__file__).resolve()
assert package.is_relative_to(pathlib.Path(sys.prefix).resolve()), package
mi.set_variant("scalar_spectral_polarized")
loaded = mi.load_dict(scene())
bsdfs = sorted(str(s.bsdf()).split("[")[0] for s in loaded.shapes())
image = mi.render(loaded, seed=3)
print(json.dumps({"version": mitsuba_birefringent.__version__, "bsdfs": bsdfs,
                  "library": str(mitsuba_birefringent.library_path()),
                  "image": [float(x) for x in image.array]}))  # no numpy here
'''

# An XML scene for the console script (the plate alone).
XML = """<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="6"/><integer name="height" value="4"/></film>
        <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><translate z="-2"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
    <shape type="rectangle">
        <bsdf type="thinbirefringent"><string name="material" value="quartz"/></bsdf>
    </shape>
</scene>
"""


def pyproject() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)


def build_pins() -> dict[str, str]:
    """`name -> version` of the `==` pins of pyproject.toml's build requirements."""
    return dict(r.split("==") for r in pyproject()["build-system"]["requires"])


def clean_env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}


def check(args: list[str], **kw) -> subprocess.CompletedProcess:
    result = subprocess.run(args, capture_output=True, text=True, env=clean_env(), timeout=900, **kw)
    assert result.returncode == 0, f"{args}:\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}"
    return result


def test_version_has_one_source():
    # Cargo.toml's version is the distribution's (written by the build backend) and the
    # core's (compiled into the library).
    with open(ROOT / "Cargo.toml", "rb") as f:
        cargo = tomllib.load(f)["package"]["version"]
    assert "version" not in pyproject()["project"]
    assert mitsuba_birefringent.__version__ == cargo
    assert mitsuba_birefringent.core_version() == cargo


def test_build_pins_are_requirements_pins():
    # The wheel is built against pyproject.toml's pins, .venv/ (and the tests) use
    # requirements.txt's: they must be the same versions.
    text = (ROOT / "requirements.txt").read_text()
    pinned = dict(re.findall(r"^([A-Za-z0-9_.-]+)==(\S+)", text, re.M))
    pins = build_pins()
    assert set(pins) == {"mitsuba", "drjit", "nanobind"}
    assert {k: pinned[k] for k in pins} == pins


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> pathlib.Path:
    out = tmp_path_factory.mktemp("wheelhouse")
    check([sys.executable, *PIP, "wheel", "--no-deps", "-w", str(out), str(ROOT)], cwd=ROOT)
    (path,) = out.glob("*.whl")
    return path


def test_wheel_is_platform_tagged_and_pinned(wheel):
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    version = mitsuba_birefringent.__version__
    assert wheel.name == f"mitsuba_birefringent-{version}-{python}-{python}-{platform}.whl"
    info = f"mitsuba_birefringent-{version}.dist-info"
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        wheel_file = z.read(f"{info}/WHEEL").decode()
        metadata = z.read(f"{info}/METADATA").decode()
        entry_points = z.read(f"{info}/entry_points.txt").decode()
    assert "Root-Is-Purelib: false" in wheel_file
    assert f"Tag: {python}-{python}-{platform}" in wheel_file
    requires = re.findall(r"^Requires-Dist: (.*)$", metadata, re.M)
    assert sorted(requires) == sorted(f"{k}=={v}" for k, v in build_pins().items() if k != "nanobind")
    assert "mitsuba-birefringent = mitsuba_birefringent.cli:main" in entry_points
    assert {"mitsuba_birefringent/__init__.py", "mitsuba_birefringent/cli.py",
            "mitsuba_birefringent/libmitsuba_birefringent.so", f"{info}/RECORD"} <= names


def test_wheel_installs_and_renders_in_a_fresh_venv(wheel, tmp_path):
    venv, elsewhere = tmp_path / "venv", tmp_path / "elsewhere"
    elsewhere.mkdir()
    check([sys.executable, "-m", "venv", str(venv)])
    python = str(venv / "bin" / "python")
    check([python, *PIP, "install", f"mitsuba=={build_pins()['mitsuba']}"], cwd=elsewhere)
    check([python, *PIP, "install", str(wheel)], cwd=elsewhere)

    result = check([python, "-c", CHECK, str(ROOT)], cwd=elsewhere)
    fresh = json.loads(result.stdout.strip().splitlines()[-1])
    assert fresh["version"] == mitsuba_birefringent.__version__
    assert fresh["bsdfs"] == ["Birefringent", "SmoothDiffuse", "ThinBirefringent"], fresh["bsdfs"]

    # The same render with the repository's build: the wheel's library is the same library.
    namespace: dict = {}
    exec(SCENE, namespace)
    mi.set_variant("scalar_spectral_polarized")
    here = np.array(mi.render(mi.load_dict(namespace["scene"]()), seed=3)).ravel()
    image = np.array(fresh["image"])
    assert np.isfinite(image).all() and image.mean() > 0.05, image.mean()
    # Same code, same samples: equal to float rounding (measured: identical).
    print(f"fresh venv vs repository build: mean {image.mean():.4f}, max difference {np.abs(image - here).max():.2e}")
    assert np.allclose(image, here, rtol=1e-5, atol=1e-6), np.abs(image - here).max()

    # The library finds libmitsuba and libdrjit-core beside itself, not in the build tree.
    library = fresh["library"]
    dynamic = check(["readelf", "-d", library]).stdout
    (runpath,) = re.findall(r"\(RUNPATH\)\s+Library runpath: \[(.*)\]", dynamic)
    assert runpath == "$ORIGIN/../mitsuba:$ORIGIN/../drjit"
    site = pathlib.Path(library).resolve().parents[1]
    resolved = check(["ldd", library]).stdout
    assert "not found" not in resolved, resolved
    for lib, folder in (("libmitsuba.so", "mitsuba"), ("libdrjit-core.so", "drjit")):
        (target,) = re.findall(rf"{re.escape(lib)} => (\S+)", resolved)
        assert pathlib.Path(target).resolve() == (site / folder / lib).resolve(), target

    # The console script renders an XML scene there too.
    (elsewhere / "plate.xml").write_text(XML)
    check([str(venv / "bin" / "mitsuba-birefringent"), "-m", "scalar_spectral_polarized",
           "plate.xml"], cwd=elsewhere)
    assert (elsewhere / "plate.exr").is_file()

"""The likeliest mistakes of a Mitsuba user new to these plugins, and what each gives: an error
at load whose message names the parameter and says what to give, or, for input that is valid but
probably not what was meant, a warning at load that says the same. None of them may give a
silently wrong image.

`MISTAKES` lists them, each with why it is likely (one line), what the user writes and the texts
the message must hold: the parameter's name and the fix. Where the mistake is valid input (a
default, a unit), the test also checks what the plugin then does (the stressed glass is that
glass, bit for bit). The JIT, CUDA and command-line cases run in subprocesses (a failed symbolic
render leaves Dr.Jit's state to the process; a CUDA variant may half-initialise).
"""

from __future__ import annotations

import contextlib
import json
import math
import pathlib
import re
import subprocess
import sys
from dataclasses import dataclass, field

import mitsuba as mi
import numpy as np
import pytest

import mitsuba_birefringent

from bfr_helpers import context, surface_interaction

ROOT = pathlib.Path(__file__).resolve().parents[2]
POLARIZED = "scalar_spectral_polarized"
#: The crystal names the README gives (`material`), which every list of them must use.
README_CRYSTALS = ("calcite", "quartz", "sapphire", "rutile", "mgf2", "linbo3", "bbo", "kdp")


@dataclass
class Mistake:
    key: str
    why: str  # one line: why a Mitsuba user is likely to make it
    action: str  # "error" or "warning" at load, "render" (a JIT render), "cuda", "calculator"
    params: dict = field(default_factory=dict)  # the plugin's dict (type included)
    want: tuple[str, ...] = ()  # texts the message must hold: the parameter, then the fix
    variant: str = POLARIZED


RGB = {"type": "rgb", "value": [1.5, 1.52, 1.55]}
SPECTRUM = {"type": "spectrum", "value": [(400.0, 1.56), (700.0, 1.54)]}
PLATE, CRYSTAL, STACK = "thinbirefringent", "birefringent", "birefringentstack"
QUARTZ_PLATE = {"type": PLATE, "material": "quartz", "thickness": 30.0, "optic_axis": [1.0, 1.0, 0.0]}

MISTAKES = [
    Mistake("stress_without_material",
            "a photoelasticity user describes stressed glass by its stress birefringence alone",
            "warning", {"type": PLATE, "thickness": 3000.0, "birefringence": 2e-4},
            ('"birefringence"', "isotropic glass", "1.5046", "give eta_o = eta_e")),
    Mistake("thickness_in_millimetres",
            "glass plates are thought of in millimetres: 3 mm written 3.0 (unit: um)",
            "warning", {"type": PLATE, "eta_o": 1.5, "eta_e": 1.5, "thickness": 3.0,
                        "birefringence": 2e-4},
            ("thickness", "retardance of 0.600 nm", "a 3 mm plate is 3000 µm")),
    Mistake("thickness_in_metres",
            "Mitsuba scenes are usually in metres: 3 mm written 0.003",
            "warning", {"type": PLATE, "material": "quartz", "thickness": 0.003},
            ("thickness", "thinner than 0.01 µm", "in metres", "thickness is in µm")),
    Mistake("axis_angle_in_radians",
            "NumPy's trigonometry is in radians: 45 degrees written np.pi / 4",
            "warning", {"type": PLATE, "eta_o": 1.5, "eta_e": 1.5, "thickness": 3000.0,
                        "birefringence": 2e-4, "axis_angle": math.pi / 4},
            ("axis_angle", "π/4 in radians (45 degrees)", "is in degrees")),
    Mistake("index_as_rgb",
            "Mitsuba's dielectric-like parameters often take colours; a dispersive glass as rgb",
            "error", {"type": PLATE, "eta_o": RGB, "eta_e": 1.5},
            ('"eta_o" must be a float, got rgb', '"material"', "dispersion")),
    Mistake("index_as_spectrum",
            "a measured dispersion curve given as a spectrum",
            "error", {"type": CRYSTAL, "eta_o": SPECTRUM, "eta_e": 1.5},
            ('"eta_o" must be a float, got spectrum', '"material"', "dispersion")),
    Mistake("int_ior_on_a_plate",
            "thindielectric's index is int_ior: copied onto the plate",
            "error", {"type": PLATE, "int_ior": 1.5},
            ('"int_ior" is not a parameter', "eta_o and eta_e", "ext_ior and exit_ior")),
    Mistake("int_ior_on_a_crystal",
            "dielectric's index is int_ior: copied onto the crystal",
            "error", {"type": CRYSTAL, "int_ior": 1.6},
            ('"int_ior" is not a parameter', "eta_o and eta_e", '"material"')),
    Mistake("thickness_on_a_crystal",
            "the two plugins are confused: a thickness for the bulk crystal",
            "error", {"type": CRYSTAL, "material": "calcite", "thickness": 1000.0},
            ('"thickness" is not a parameter', '"thinbirefringent"')),
    Mistake("world_axis_on_a_plate",
            "the bulk crystal's optic_axis_space given to a plate",
            "error", {"type": PLATE, "material": "quartz", "optic_axis_space": "world"},
            ('"optic_axis_space" is not a parameter', "axis_angle", '"birefringent"')),
    Mistake("axis_as_a_float",
            "an XML <float> for the axis (Mitsuba's parameters are mostly floats)",
            "error", {"type": CRYSTAL, "material": "calcite", "optic_axis": 1.0},
            ('"optic_axis" must be a vector, got float', '<vector name="optic_axis"', "[1, 0, 0]")),
    Mistake("misspelt_crystal",
            "a crystal's name misspelt (or a name other tools use)",
            "error", {"type": PLATE, "material": "quarts", "thickness": 30.0},
            ("material: unknown crystal 'quarts'", *README_CRYSTALS, "eta_o and eta_e")),
    Mistake("no_material",
            "a plugin tried with its type alone, as Mitsuba's own plugins can be",
            "warning", {"type": PLATE},
            ('material = "calcite"', "thickness = 1 um", "Give them to choose")),
    Mistake("crystal_without_axis",
            "an axis left to its default on a crystal object whose faces have their own frames",
            "warning", {"type": CRYSTAL, "material": "calcite"},
            ("optic_axis = [1, 0, 0] in the shading frame", 'optic_axis_space "world"')),
    Mistake("axis_space_capitalised",
            "a string value written as a label ('World')",
            "error", {"type": CRYSTAL, "material": "calcite", "optic_axis_space": "World"},
            ('"optic_axis_space" must be "local"', '"world"')),
    Mistake("crystal_in_an_rgb_variant",
            "scalar_rgb is Mitsuba's default variant; double refraction needs polarisation",
            "error", {"type": CRYSTAL, "material": "calcite"},
            ("double refraction", "needs a polarized variant", "scalar_spectral_polarized"),
            variant="scalar_rgb"),
    Mistake("thickness_as_a_colour_bitmap",
            "a thickness map loaded like any image (Mitsuba converts it to spectra)",
            "error", {"type": PLATE, "material": "quartz",
                      "thickness": "COLOUR_BITMAP"},
            ('"thickness" is a number (micrometres)', 'raw="true"')),
    Mistake("jit_render_in_symbolic_mode",
            "the llvm variants render in symbolic mode by default, which the plugins cannot",
            "render", QUARTZ_PLATE, ("[ThinBirefringent]", "drjit.JitFlag.SymbolicLoops",
                                     "drjit.JitFlag.SymbolicCalls",
                                     "mitsuba_birefringent.evaluated_mode()")),
    Mistake("cuda_variant",
            "cuda variants are the fast ones of Mitsuba's wheel; this machine has no CUDA device",
            "cuda", {}, ('variant "cuda_ad_rgb" needs a CUDA device', 'use "llvm_ad_rgb"')),
    Mistake("calculator_thickness_without_unit",
            "the plugin's parameter is `thickness`; the calculator's carries its unit",
            "calculator", {}, ("thickness: unknown field", "did you mean thickness_um")),
    Mistake("plate_without_axis",
            "a plate given its crystal and thickness only, as thindielectric needs no more",
            "warning", {"type": PLATE, "material": "quartz", "thickness": 30.0},
            ("optic_axis = [1, 0, 0]", "between polarisers along x or y", "give optic_axis",
             "axis_angle")),
    Mistake("crystal_axis_without_space",
            "the axis of a crystal object given, its frame left to the default",
            "warning", {"type": CRYSTAL, "material": "calcite", "optic_axis": [0, 0, 1]},
            ('optic_axis_space = "local"', "every face of a cube", 'optic_axis_space "world"')),
    Mistake("bandwidth_in_rgb",
            "a scene written for a spectral variant rendered in Mitsuba's default, scalar_rgb",
            "warning", {**QUARTZ_PLATE, "filter_bandwidth": 10.0},
            ('"filter_bandwidth" = 10 nm is ignored in this variant', "sRGB channels",
             "spectral variants"), variant="scalar_rgb"),
    Mistake("stack_bandwidth_in_rgb",
            "the same with a stack",
            "warning", {"type": STACK, "filter_bandwidth": 10.0, "layer": QUARTZ_PLATE},
            ('[BirefringentStack] "filter_bandwidth" = 10 nm is ignored', "spectral variants"),
            variant="scalar_rgb"),
    Mistake("layer_without_thickness",
            "a stack's layer given its indices only (a tape's thickness forgotten)",
            "warning", {"type": STACK, "quarter": QUARTZ_PLATE,
                        "tape": {"type": PLATE, "eta_o": 1.47, "eta_e": 1.48,
                                 "axis_angle": 45.0}},
            ('not given to "tape"', "thickness = 1 um", "a 3 mm plate is 3000")),
    Mistake("misspelt_parameter",
            "a parameter's name misspelt (thicknes): the default it leaves is not the news",
            "error alone", {"type": PLATE, "material": "quartz", "thicknes": 30.0,
                            "optic_axis": [1, 1, 0]},
            ("unreferenced property", '"thicknes"')),
]


class Capture(mi.Appender):
    """Keeps the text of every message logged (warnings and errors)."""

    def __init__(self):
        super().__init__()
        self.messages: list[str] = []

    def append(self, level, text):
        self.messages.append(text)

    def log_progress(self, *args):
        pass


@contextlib.contextmanager
def captured_log():
    logger = mi.logger()
    capture = Capture()
    logger.add_appender(capture)
    try:
        yield capture.messages
    finally:
        logger.remove_appender(capture)


def resolved(params: dict) -> dict:
    out = dict(params)
    if out.get("thickness") == "COLOUR_BITMAP":
        out["thickness"] = {"type": "bitmap", "bitmap": mi.Bitmap(np.full((2, 2, 3), 3.0, np.float32))}
    return out


def load(m: Mistake) -> tuple[Exception | None, str]:
    """(the load's exception, the warnings it logged)."""
    mi.set_variant(m.variant)
    with captured_log() as log:
        try:
            mi.load_dict(resolved(m.params))
            error = None
        except Exception as e:  # noqa: BLE001 - the message is what is tested
            error = e
    return error, "\n".join(log)


JIT_SCRIPT = """
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
import mitsuba_birefringent
scene = mi.load_dict({"type": "scene", "integrator": {"type": "path"},
    "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 4, "height": 4}},
    "sky": {"type": "constant"},
    "pane": {"type": "sphere", "bsdf": BSDF}})
mi.render(scene)
"""

CUDA_SCRIPT = """
import mitsuba as mi
import mitsuba_birefringent
try:
    mi.set_variant("cuda_ad_rgb")
except Exception as e:
    print("SET_VARIANT:", e)
    raise SystemExit(0)
try:
    mi.load_dict({"type": "thinbirefringent", "material": "quartz", "thickness": 20.0})
except Exception as e:
    print("LOAD:", e)
"""


def last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1] if lines else ""


def message(m: Mistake) -> str:
    """What the user sees of mistake `m`: the error's message, the warnings logged, or the last
    line of a script's error output."""
    if m.action in ("error", "error alone", "warning"):
        error, warnings = load(m)
        if m.action.startswith("error"):
            assert error is not None, f"{m.key}: loaded without an error (warnings: {warnings!r})"
            if m.action == "error alone":
                assert warnings == "", f"{m.key}: warned before the error: {warnings}"
            return str(error)
        assert error is None, f"{m.key}: refused: {error}"
        return warnings
    if m.action == "render":
        script = JIT_SCRIPT.replace("BSDF", repr(m.params))
        r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                           timeout=300)
        assert r.returncode != 0
        return last_line(r.stderr)
    if m.action == "cuda":
        r = subprocess.run([sys.executable, "-c", CUDA_SCRIPT], capture_output=True, text=True,
                           timeout=300)
        assert r.returncode == 0, r.stderr
        return last_line(r.stdout)
    assert m.action == "calculator"
    r = subprocess.run([str(ROOT / "target" / "release" / "birefringence"), "slab"],
                       input=json.dumps({"wavelength_nm": 550, "eta_o": 1.5, "eta_e": 1.6,
                                         "optic_axis": [1, 0, 0], "theta_deg": 0,
                                         "thickness": 3000}),
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    return json.loads(r.stdout)["error"]


def test_the_mistakes_are_distinct():
    assert len({m.key for m in MISTAKES}) == len(MISTAKES)
    assert all(m.why and m.want for m in MISTAKES)


@pytest.mark.parametrize("m", MISTAKES, ids=lambda m: m.key)
def test_each_mistake_names_the_parameter_and_the_fix(m):
    text = message(m)
    missing = [w for w in m.want if w not in text]
    assert not missing, f"{m.key}: {missing} not in:\n{text}"


def test_the_cli_refuses_a_cuda_variant_with_the_plugins_message(tmp_path):
    """mitsuba-birefringent -m cuda_ad_rgb: the plugins' refusal, not Dr.Jit's (without a GPU)
    or a refusal at load (with one)."""
    xml = tmp_path / "plate.xml"
    xml.write_text('<scene version="3.0.0"><bsdf type="thinbirefringent">'
                   '<string name="material" value="quartz"/></bsdf></scene>')
    r = subprocess.run([str(ROOT / ".venv" / "bin" / "mitsuba-birefringent"), "-m", "cuda_ad_rgb",
                        str(xml)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 1
    line = last_line(r.stderr)
    assert line.startswith('mitsuba-birefringent: error: variant "cuda_ad_rgb" needs a CUDA device')
    assert 'use "llvm_ad_rgb"' in line, r.stderr


def test_a_stressed_plate_without_material_is_the_stated_glass():
    """What the warning says is what the plate is: the same answers, bit for bit, as the glass
    given explicitly (eta_o = eta_e = 1.5046) with the same stress."""
    mi.set_variant(POLARIZED)
    stress = {"thickness": 3000.0, "birefringence": 2e-4, "axis_angle": 30.0}
    implicit = mi.load_dict({"type": PLATE, **stress})
    explicit = mi.load_dict({"type": PLATE, "eta_o": 1.5046, "eta_e": 1.5046, **stress})
    calcite = mi.load_dict({"type": PLATE, "material": "calcite", **stress})
    rng = np.random.default_rng(4)
    for _ in range(8):
        w = rng.normal(size=3)
        w[2] = abs(w[2]) + 0.1
        si = surface_interaction(w / np.linalg.norm(w))
        u = float(rng.uniform())
        a = implicit.sample(context(), si, u, mi.Point2f(0.5, 0.5))
        b = explicit.sample(context(), si, u, mi.Point2f(0.5, 0.5))
        c = calcite.sample(context(), si, u, mi.Point2f(0.5, 0.5))
        assert np.array_equal(np.array(a[1]), np.array(b[1]))
        assert not np.allclose(np.array(a[1]), np.array(c[1]))
    assert mi.traverse(implicit)["eta_o"] == pytest.approx(1.5046)


def test_a_default_is_warned_of_once_and_explicit_values_are_silent():
    """The warnings are for defaults and doubtful units only: a fully specified plate and
    crystal load without any."""
    for variant_name, params in ((POLARIZED, QUARTZ_PLATE),
                                 (POLARIZED, {"type": PLATE, "eta_o": 1.5, "eta_e": 1.5,
                                              "thickness": 3000.0, "birefringence": 2e-4,
                                              "axis_angle": 45.0}),
                                 (POLARIZED, {"type": PLATE, "eta_o": 1.5, "eta_e": 1.5,
                                              "thickness": 3000.0}),
                                 (POLARIZED, {"type": CRYSTAL, "material": "calcite",
                                              "optic_axis": [0, 0, 1], "optic_axis_space": "world"}),
                                 (POLARIZED, {"type": CRYSTAL, "material": "calcite",
                                              "optic_axis": [0, 0, 1], "optic_axis_space": "local"}),
                                 (POLARIZED, {"type": CRYSTAL, "eta_o": 1.5, "eta_e": 1.5}),
                                 (POLARIZED, {"type": STACK, "a": QUARTZ_PLATE,
                                              "b": {**QUARTZ_PLATE, "optic_axis": [0, 1, 0]}}),
                                 ("scalar_rgb", {**QUARTZ_PLATE, "filter_bandwidth": 0.0})):
        error, warnings = load(Mistake("ok", "", "warning", params, variant=variant_name))
        assert error is None and warnings == "", f"{params}: {warnings}"


@pytest.mark.parametrize("name", ["eta_e", "kappa_o", "kappa_e"])
def test_other_constants_given_as_colours_are_named(name):
    mi.set_variant(POLARIZED)
    params = {"type": PLATE, "eta_o": 1.5, "eta_e": 1.5, name: RGB}
    with pytest.raises(RuntimeError, match=rf'"{name}" must be a float, got rgb'):
        mi.load_dict(params)


def test_every_list_of_crystals_uses_the_readme_names():
    """The names README.md gives for `material` are the canonical ones: the plugins' and the
    calculator's lists of known crystals, and plugin/README.md's table, use exactly them."""
    readme = (ROOT / "README.md").read_text()
    listed = re.search(r"The named crystals are (.+?) \(cited", readme, re.S).group(1)
    assert tuple(re.findall(r"`(\w+)`", listed)) == README_CRYSTALS
    mi.set_variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        mi.load_dict({"type": PLATE, "material": "nothing"})
    known = re.search(r"names: (.+?) \(case", str(e.value)).group(1)
    assert [n.split(" (")[0] for n in known.split(", ")] == list(README_CRYSTALS)
    table = (ROOT / "plugin" / "README.md").read_text()
    row = next(line for line in table.splitlines() if line.startswith("| `material` |"))
    assert all(f"`{n}`" in row for n in README_CRYSTALS), row
    for name in README_CRYSTALS:
        mi.load_dict({"type": PLATE, "material": name, "thickness": 10.0})


@pytest.mark.parametrize("m", [m for m in MISTAKES if m.action in ("error", "error alone", "warning")
                               and m.variant == POLARIZED], ids=lambda m: m.key)
def test_a_jit_variant_says_the_same(m):
    """The same mistakes in llvm_ad_spectral_polarized (loading only: no render) give the same
    messages: the shim's checks do not depend on the variant."""
    jit = Mistake(m.key, m.why, m.action, m.params, m.want, variant="llvm_ad_spectral_polarized")
    text = message(jit)
    missing = [w for w in m.want if w not in text]
    assert not missing, f"{m.key}: {missing} not in:\n{text}"


@pytest.mark.parametrize("params", [{"type": PLATE, "material": "quartz", "thickness": -1.0},
                                    {"type": STACK},
                                    {"type": CRYSTAL, "eta_o": -1.0, "eta_e": 1.5}],
                         ids=lambda p: p["type"])
def test_each_plugins_messages_are_surfaced(params):
    """Every plugin's messages carry its class's tag, which the wrapped `mi.render` looks for in
    the exceptions Dr.Jit chains (messages.py): the stack's too. (names.py writes the plugins
    once, with their classes: a class named there otherwise than in cpp/src fails here.)"""
    from mitsuba_birefringent import messages, names

    mi.set_variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        mi.load_dict(params)
    tag = f"[{names.CLASSES[params['type']]}] "
    assert tag in str(e.value)
    plugin = RuntimeError(str(e.value)[str(e.value).index(tag):])
    custom = RuntimeError("drjit.custom(): error while performing a custom differentiable "
                          "operation. (see above)")
    custom.__cause__ = plugin
    assert messages.plugin_message(custom) == str(plugin)


def test_render_analytic_prints_each_load_warning_once():
    """A channel render loads the scene once per channel: a warning at load (here a plate's
    default axis) is printed by the first pass only."""
    import sys as _sys

    _sys.path.insert(0, str(ROOT / "scenes"))
    from _common import backlight, layer, ortho_sensor

    scene = {"type": "scene", "integrator": {"type": "path"},
             "sensor": ortho_sensor(2, 2, 1, 1.0, 1.0), "light": backlight(-3.0, 4.0),
             "plate": layer(0.0, 2, 2, {"type": PLATE, "material": "quartz", "thickness": 30.0})}
    with captured_log() as log:
        mitsuba_birefringent.render_analytic(scene, spp=1)
    said = [m for m in log if "optic_axis = [1, 0, 0]" in m]
    assert len(said) == 1, log

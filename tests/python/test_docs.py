"""The documentation stays true to the code: docs/architecture.md maps every module, the code
cites only documents (and sections) that exist, and the plugins' parameter docs (the leading
/**! block of each cpp/src/<plugin>.cpp) name exactly the properties each plugin reads and the
parameters it exposes, with plugin/README.md's tables generated from them.
"""

from __future__ import annotations

import importlib.util
import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"

#: The modules docs/architecture.md must map: the core, the ABI header, the shim, the package
#: and its build backend.
MODULE_GLOBS = ("src/**/*.rs", "build.rs", "cpp/build.rs", "cpp/src/*",
                "plugin/mitsuba_birefringent/*.py", "build_backend/*.py")
#: Where citations of docs/ are looked for.
CITING = ("src", "tests", "cpp", "plugin", "scenes", "tools", "bench", "examples", "build_backend",
          "docs", "Makefile", "README.md", "pyproject.toml")
TEXT_SUFFIXES = (".rs", ".h", ".cpp", ".py", ".md", ".toml", ".sh", ".xml", "")
#: Citations of notes that are not part of the repository (replaced by docs/).
STALE = re.compile(r"physics notes|notes on building|notes on Mitsuba|\(notes, section|seed eqs?\.")


def plugin_docs():
    spec = importlib.util.spec_from_file_location("plugin_docs", ROOT / "tools" / "plugin_docs.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["plugin_docs"] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def text_files():
    for entry in CITING:
        path = ROOT / entry
        paths = [path] if path.is_file() else path.rglob("*")
        for p in paths:
            if p.is_file() and "target" not in p.parts and p.suffix in TEXT_SUFFIXES:
                yield p


def test_architecture_map_lists_every_module():
    text = (DOCS / "architecture.md").read_text()
    mapped = re.findall(r"^- `([^`]+)` — \S", text, re.M)
    assert len(mapped) == len(set(mapped)), "a module is listed twice"
    existing = {str(p.relative_to(ROOT)) for g in MODULE_GLOBS for p in ROOT.glob(g) if p.is_file()}
    existing = {p for p in existing if "__pycache__" not in p and not p.endswith(".so")}
    missing, extra = sorted(existing - set(mapped)), sorted(set(mapped) - existing)
    assert not missing, f"modules missing from the map: {missing}"
    assert not extra, f"the map lists modules that do not exist: {extra}"


def test_code_cites_only_existing_documents_and_sections():
    cited = 0
    for path in text_files():
        text = path.read_text(errors="replace")
        rel = path.relative_to(ROOT)
        if rel != pathlib.Path("tests/python/test_docs.py"):
            stale = STALE.findall(text)
            assert not stale, f"{rel} cites notes outside the repository: {stale}"
        for doc, section in re.findall(r"docs/(\w+)\.md(?:`)?(?:,? §(\d+))?", text):
            cited += 1
            target = DOCS / f"{doc}.md"
            assert target.is_file(), f"{rel} cites docs/{doc}.md, which does not exist"
            if section:
                headings = re.findall(r"^## (\d+)\. ", target.read_text(), re.M)
                assert section in headings, f"{rel} cites docs/{doc}.md §{section}: no such section"
    assert cited > 10  # the search finds the citations


def test_plugin_readme_tables_are_generated_from_the_sources():
    result = subprocess.run([sys.executable, str(ROOT / "tools" / "plugin_docs.py"), "--check"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


def source_names(path: pathlib.Path) -> tuple[set[str], set[str]]:
    """(properties the plugin's constructor reads, parameters its `traverse` exposes)."""
    source = path.read_text()
    read = r'(?:props\.\w+(?:<[^>]*>)?\(|(?:parse_ior|scalar_texture<[^>]*>)\(\s*props,\s*)\s*"(\w+)"'
    names = set(re.findall(read, source))
    common = (path.parent / "params.h").read_text()
    # The parsers of params.h read properties too: the material, the channel, the band.
    for call, definition in (("parse_material(props", "inline MaterialParams parse_material"),
                             ("parse_channel<Spectrum>(props", "std::string parse_channel"),
                             ("parse_filter_bandwidth<Spectrum>(props",
                              "double parse_filter_bandwidth")):
        if call in source:
            body = common[common.index(definition):]
            names |= set(re.findall(read, body[:body.index("\n}\n")]))
    exposed = set(re.findall(r'cb->put\("(\w+)"', source))
    # The parameters differentiable.h exposes (their handles in the JIT variants).
    if "m_diff.traverse(cb)" in source:
        exposed |= set(re.findall(r'cb->put\("(\w+)"', (path.parent / "differentiable.h").read_text()))
    return names, exposed


@pytest.mark.parametrize("plugin", ["thinbirefringent", "birefringent"])
def test_documented_parameters_are_the_ones_the_plugin_reads(plugin):
    path = ROOT / "cpp" / "src" / f"{plugin}.cpp"
    name, params = plugin_docs().parameters(path.read_text())
    assert name == plugin
    read, exposed = source_names(path)
    documented = {n for p in params for n in p.names()}
    assert documented == read, f"documented {sorted(documented ^ read)} differ from those read"
    marked = {n for p in params if "exposed" in p.flags for n in p.names()}
    assert marked == exposed, f"exposed in the docs vs traverse: {sorted(marked ^ exposed)}"


def test_plugin_docs_parser_reads_mitsuba_style_rows():
    # The parser on a block in the format of Mitsuba's own plugins (multi-line cells, flags,
    # the default at the end of the meaning, several names in one row).
    block = """/**!

Example plate (:monosp:`example`)
---------------------------------

.. pluginparameters::
 :extra-rows: 1

 * - eta_o, eta_e
   - |float| or |texture|
   - Indices of ``the`` plate,
     continued. (Default: |false|)
   - |exposed|, |differentiable|

 * - flag
   - |bool|
   - On or off.

Prose that is not a parameter.
*/"""
    name, params = plugin_docs().parameters(block)
    assert name == "example"
    assert [p.names() for p in params] == [["eta_o", "eta_e"], ["flag"]]
    first = params[0]
    assert (first.type, first.meaning, first.default, first.flags) == (
        "float or texture", "Indices of `the` plate, continued.", "`false`",
        "exposed, differentiable")
    assert params[1].default == "—" and params[1].flags == ""


def test_benchmark_page_and_summary_are_generated_from_the_results(tmp_path):
    """docs/benchmarks.md's tables and README.md's summary of them are what bench/readme.py
    writes from bench/results.json (regenerate them after a benchmark: make bench-scenes or
    make bench-overhead do)."""
    page, readme = tmp_path / "benchmarks.md", tmp_path / "README.md"
    page.write_text((DOCS / "benchmarks.md").read_text())
    readme.write_text((ROOT / "README.md").read_text())
    result = subprocess.run([sys.executable, str(ROOT / "bench" / "readme.py"),
                             str(ROOT / "bench" / "results.json"), str(page), str(readme)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    # The page links to the repository's files relative to its own folder: from tmp_path that
    # path differs, and is put back as from docs/.
    written = re.sub(r"\]\([^)\s]*?bench/", "](../bench/", page.read_text())
    assert written == (DOCS / "benchmarks.md").read_text()
    assert readme.read_text() == (ROOT / "README.md").read_text()


#: Numbers as the documents write them.
NUMBER_WORDS = {1: "one", 2: "two", 3: "three", 4: "four", 5: "five", 6: "six"}
#: A count of plugins in prose ("three BSDF plugins", "both plugins").
PLUGIN_COUNT = re.compile(r"\b(one|two|three|four|five|six|both)\s+(?:Mitsuba\s+)?(?:BSDF\s+)?"
                          r"plugins\b", re.IGNORECASE)


def test_the_docs_count_and_name_every_plugin():
    """README.md, plugin/README.md and docs/architecture.md name every plugin the package
    registers and count them right (no "two plugins" left when a third is added); so do the
    command's --help and the refusal of a cuda variant."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    import mitsuba_birefringent
    from mitsuba_birefringent import messages

    plugins = mitsuba_birefringent.PLUGINS
    for name in plugins:  # each is registered under that name
        assert mi.PluginManager.instance().plugin_type(name) == mi.ObjectType.BSDF, name
    count = NUMBER_WORDS[len(plugins)]
    for doc in (ROOT / "README.md", ROOT / "plugin" / "README.md", DOCS / "architecture.md"):
        text = doc.read_text(encoding="utf-8")
        for name in plugins:
            assert f"`{name}`" in text, f"{doc.name} does not name {name}"
        said = [m.group(1).lower() for m in PLUGIN_COUNT.finditer(text)]
        assert count in said, f"{doc.name} does not say {count} plugins"
        assert set(said) == {count}, f"{doc.name} counts the plugins as {sorted(set(said))}"
    help_text = subprocess.run([str(ROOT / ".venv" / "bin" / "mitsuba-birefringent"), "--help"],
                               capture_output=True, text=True, timeout=120).stdout
    refusal = messages.cuda_refusal("cuda_ad_rgb", mitsuba_birefringent.VARIANTS)
    for name in plugins:
        assert name in " ".join(help_text.split()), f"--help does not name {name}"
        assert name in refusal, refusal


def test_readme_states_the_number_of_pytest_tests():
    """README.md's `make test` row states how many pytest tests there are: the number pytest
    collects (a test added or removed without the README fails here)."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    stated = re.findall(r"(\d+) pytest tests", readme)
    assert len(stated) == 1, f"README.md states the pytest count {len(stated)} times"
    out = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q",
                          "-p", "no:cacheprovider", str(ROOT / "tests" / "python")],
                         capture_output=True, text=True, timeout=600, cwd=ROOT)
    collected = re.search(r"^(\d+) tests? collected", out.stdout, re.MULTILINE)
    assert collected, out.stdout[-2000:] + out.stderr[-2000:]
    assert int(stated[0]) == int(collected.group(1)), (
        f"README.md says {stated[0]} pytest tests; pytest collects {collected.group(1)}")

"""Every code block of README.md, plugin/README.md and docs/*.md that is a scene or a command runs
as written, at a small size: the documentation cannot drift from the product.

A block is what its info string says:

- ```` ```xml ````: a Mitsuba scene (a `<scene>`; rendered with the package's command
  `mitsuba-birefringent` in scalar_spectral_polarized, and the image must be finite and not
  black) or a fragment (a `<bsdf>`: loaded inside a scene). ```` ```xml NAME.xml ```` also saves
  it as NAME.xml, for the commands after it that name that file.
- ```` ```python ````: a script, run with .venv/bin/python.
- ```` ```sh ````: commands, run by bash (`-e -o pipefail`) with .venv/bin first on PATH.
- Any of these with the word `notest` after the language is not run (the few that set up or
  take minutes: `make setup`); `MAX_NOTEST` bounds how many there are. Blocks with another
  language or none (synopses, JSON, outputs) are not code.

Each document's blocks run in its order (a block may use the files an earlier one wrote) in a
temporary directory that links every top-level entry of the repository except `out/` (paths are
as from the root; what the blocks write stays there). "A small size": before running, image
sizes become 16 and sample counts 2 (`SMALL`: XML `<integer name="width|height|sample_count">`
and `<default name="width|height|spp">`, Python `"width": N`, `"height": N`,
`"sample_count": N`, `spp=N`, command-line `-D width=N`, `--spp N`, `--width N`, `--height N`);
nothing else is changed.
"""

from __future__ import annotations

import os
import pathlib
import re
import subprocess
import sys
from dataclasses import dataclass

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCUMENTS = [ROOT / "README.md", ROOT / "plugin" / "README.md",
             *sorted((ROOT / "docs").glob("*.md"))]
CODE = ("xml", "python", "sh")
NOT_CODE = ("", "json", "text")
#: At most this many runnable-looking blocks may be marked `notest`.
MAX_NOTEST = 3
VARIANT = "scalar_spectral_polarized"

#: (pattern, replacement) per language: the small size.
SMALL = {
    "xml": [(r'(<integer name="(?:width|height)" value=")\d+(")', r"\g<1>16\2"),
            (r'(<integer name="sample_count" value=")\d+(")', r"\g<1>2\2"),
            (r'(<default name="(?:width|height)" value=")\d+(")', r"\g<1>16\2"),
            (r'(<default name="spp" value=")\d+(")', r"\g<1>2\2")],
    "python": [(r'("(?:width|height)":\s*)\d+', r"\g<1>16"),
               (r'("sample_count":\s*)\d+', r"\g<1>2"),
               (r"\bspp=\d+", "spp=2")],
    "sh": [(r"(-D (?:width|height)=)\d+", r"\g<1>16"), (r"(-D spp=)\d+", r"\g<1>2"),
           (r"(--spp )\d+", r"\g<1>2"), (r"(--(?:width|height) )\d+", r"\g<1>16")],
}


@dataclass
class Block:
    document: pathlib.Path
    line: int
    language: str
    words: list[str]
    text: str

    def where(self) -> str:
        return f"{self.document.relative_to(ROOT)}:{self.line}"


def blocks(path: pathlib.Path) -> list[Block]:
    """The fenced code blocks of a Markdown file, in order."""
    out, lines, i = [], path.read_text(encoding="utf-8").splitlines(), 0
    while i < len(lines):
        m = re.match(r"^```(.*)$", lines[i])
        if m:
            words = m.group(1).split()
            end = next(j for j in range(i + 1, len(lines)) if lines[j].startswith("```"))
            out.append(Block(path, i + 1, words[0] if words else "", words[1:],
                             "\n".join(lines[i + 1:end]) + "\n"))
            i = end
        i += 1
    return out


def small(block: Block) -> str:
    text = block.text
    for pattern, replacement in SMALL[block.language]:
        text = re.sub(pattern, replacement, text)
    return text


def farm(tmp: pathlib.Path) -> pathlib.Path:
    """A directory that looks like the repository's root (links), where outputs stay."""
    for entry in ROOT.iterdir():
        if entry.name not in ("out", ".git"):
            (tmp / entry.name).symlink_to(entry)
    return tmp


def environment() -> dict[str, str]:
    env = dict(os.environ)
    env["PATH"] = f"{ROOT / '.venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    return env


def run(cmd: list[str], cwd: pathlib.Path, what: Block, timeout: int = 600) -> None:
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                       env=environment())
    assert r.returncode == 0, (f"{what.where()}: the {what.language} block failed "
                               f"({' '.join(cmd)}):\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")


def check_image(path: pathlib.Path, what: Block) -> None:
    import mitsuba as mi
    import numpy as np

    mi.set_variant("scalar_rgb")
    image = np.array(mi.Bitmap(str(path)), dtype=np.float64)
    assert np.isfinite(image).all(), f"{what.where()}: non-finite pixels"
    assert np.abs(image).mean() > 0, f"{what.where()}: a black image"


def run_xml(block: Block, n: int, cwd: pathlib.Path) -> None:
    text = small(block)
    if "<scene" not in text:  # a fragment: a BSDF inside a scene, loaded
        text = f'<scene version="3.0.0">\n{text}</scene>\n'
        script = cwd / f"block{n}_load.py"
        script.write_text("import sys, mitsuba as mi\nmi.set_variant(sys.argv[1])\n"
                          "import mitsuba_birefringent\nmi.load_file(sys.argv[2])\n")
        path = cwd / f"block{n}.xml"
        path.write_text(text)
        run([sys.executable, str(script), VARIANT, str(path)], cwd, block)
        return
    name = next((w for w in block.words if w.endswith(".xml")), f"block{n}.xml")
    (cwd / name).write_text(text)
    out = cwd / f"block{n}.exr"
    run(["mitsuba-birefringent", "-m", VARIANT, "-o", str(out), name], cwd, block)
    check_image(out, block)


def run_block(block: Block, n: int, cwd: pathlib.Path) -> None:
    if block.language == "xml":
        run_xml(block, n, cwd)
    elif block.language == "python":
        script = cwd / f"block{n}.py"
        script.write_text(small(block))
        run([sys.executable, str(script)], cwd, block)
    else:
        run(["bash", "-e", "-o", "pipefail", "-c", small(block)], cwd, block)


def test_blocks_are_marked():
    """Every block is code, a marked exception, or plainly not code; the exceptions are few."""
    notest = []
    for doc in DOCUMENTS:
        for b in blocks(doc):
            assert b.language in CODE + NOT_CODE, (
                f"{b.where()}: block of language {b.language!r}: use one of {CODE} (run by "
                f"tests/python/test_docs_examples.py) or {NOT_CODE} (not code)")
            if b.language in CODE and "notest" in b.words:
                notest.append(b.where())
    assert len(notest) <= MAX_NOTEST, f"too many blocks are not run: {notest}"


def test_the_small_size_rewrites_what_the_examples_use():
    """The substitutions reach the sizes the documents' scenes give (else the test would render
    them at full size): every scene block and every scene dict gets a film of 16 x 16."""
    scenes = [b for doc in DOCUMENTS for b in blocks(doc)
              if b.language in ("xml", "python") and "hdrfilm" in b.text and "notest" not in b.words]
    assert scenes
    for b in scenes:
        text = small(b)
        sizes = re.findall(r'"(?:width|height)":\s*(\d+)|name="(?:width|height)" value="(\d+)"', text)
        assert sizes and all("16" in s for s in sizes), f"{b.where()}: {sizes}"


@pytest.mark.parametrize("doc", DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_example_runs_as_written(doc, tmp_path):
    cwd = farm(tmp_path)
    ran = 0
    for n, b in enumerate(blocks(doc)):
        if b.language in CODE and "notest" not in b.words:
            run_block(b, n, cwd)
            ran += 1
    print(f"{doc.relative_to(ROOT)}: {ran} blocks ran")

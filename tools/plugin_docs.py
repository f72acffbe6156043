"""Writes the parameter tables of plugin/README.md from the plugins' sources.

Each plugin's C++ source (cpp/src/<plugin>.cpp) opens with a `/**! ... */` block in the style of
Mitsuba's own plugins: a title naming the plugin (``(:monosp:`name`)``) and a
``.. pluginparameters::`` list table, one row per parameter (name, type, meaning ending in
``(Default: ...)``, and optionally flags such as ``|exposed|``). This script converts the rows
to Markdown and replaces the regions of plugin/README.md between
``<!-- params:<region>:begin ... -->`` and ``<!-- params:<region>:end -->``: ``common`` holds
the rows identical in the two surface plugins (``thinbirefringent``, ``birefringent``),
``<plugin>`` the others (every row of a plugin outside those two, ``birefringentstack``).

    python tools/plugin_docs.py            # rewrite plugin/README.md
    python tools/plugin_docs.py --check    # exit 1 (with a diff) if it is out of date
"""

from __future__ import annotations

import argparse
import difflib
import re
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ROOT / "cpp" / "src"
README = ROOT / "plugin" / "README.md"

#: Mitsuba's documentation substitutions used in the blocks, as Markdown.
SUBSTITUTIONS = {"|float|": "float", "|string|": "string", "|texture|": "texture",
                 "|vector|": "vector", "|bool|": "boolean", "|int|": "integer",
                 "|spectrum|": "spectrum", "|true|": "`true`", "|false|": "`false`",
                 "|exposed|": "exposed", "|differentiable|": "differentiable",
                 "|discontinuous|": "discontinuous", "|bsdf|": "BSDF"}
#: The plugins whose shared rows form the ``common`` region.
COMMON = ("thinbirefringent", "birefringent")
DEFAULT = re.compile(r"\s*\(Default: (.*)\)\s*$", re.S)
TITLE = re.compile(r"\(:monosp:`(\w+)`\)\s*$", re.M)


@dataclass(frozen=True)
class Parameter:
    name: str  # one name, or several separated by ", " (documented together)
    type: str
    meaning: str
    default: str
    flags: str

    def names(self) -> list[str]:
        return [n.strip() for n in self.name.split(",")]

    def markdown(self) -> str:
        names = ", ".join(f"`{n}`" for n in self.names())
        return f"| {names} | {self.type} | {self.default} | {self.meaning} | {self.flags} |"


def doc_block(source: str) -> str:
    """The leading `/**! ... */` block of a plugin source."""
    if not source.startswith("/**!"):
        raise ValueError("the source does not open with a /**! ... */ block")
    return source[len("/**!"):source.index("*/")]


def markdown_text(rst: str) -> str:
    """The inline markup of the blocks as Markdown; unknown substitutions are errors."""
    text = re.sub(r"``(.+?)``", r"`\1`", " ".join(rst.split()))
    text = re.sub(r":(?:monosp|paramtype):`(.+?)`", r"`\1`", text)
    for key, value in SUBSTITUTIONS.items():
        text = text.replace(key, value)
    unknown = re.findall(r"\|\w+\|", text)
    if unknown:
        raise ValueError(f"unknown substitutions {unknown} in: {rst!r}")
    return text


def table_rows(block: str) -> list[list[str]]:
    """The cells of each row of the block's `.. pluginparameters::` list table."""
    lines = block.splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == ".. pluginparameters::")
    rows: list[list[str]] = []
    for line in lines[start + 1:]:
        if line.startswith(" * - "):
            rows.append([line[5:]])
        elif line.startswith("   - ") and rows:
            rows[-1].append(line[5:])
        elif line.startswith("     ") and rows:
            rows[-1][-1] += " " + line.strip()
        elif line.strip() and not line.startswith(" :"):
            break  # the prose after the table
    return rows


def parameters(source: str) -> tuple[str, list[Parameter]]:
    """The plugin's name and its documented parameters."""
    block = doc_block(source)
    title = TITLE.search(block)
    if not title:
        raise ValueError("the block has no title naming the plugin, (:monosp:`name`)")
    out = []
    for cells in table_rows(block):
        if len(cells) not in (3, 4):
            raise ValueError(f"a parameter row needs 3 or 4 cells, got {cells}")
        meaning, default = cells[2], "—"
        match = DEFAULT.search(meaning)
        if match:
            meaning, default = meaning[:match.start()], match.group(1)
        out.append(Parameter(cells[0].strip(), markdown_text(cells[1]), markdown_text(meaning),
                             markdown_text(default), markdown_text(cells[3]) if len(cells) == 4 else ""))
    return title.group(1), out


def plugins() -> dict[str, list[Parameter]]:
    """Every plugin source's parameters, by plugin name."""
    out = {}
    for path in sorted(SOURCES.glob("*.cpp")):
        source = path.read_text()
        if source.startswith("/**!"):
            name, params = parameters(source)
            out[name] = params
    return out


def regions() -> dict[str, str]:
    """The Markdown table of each README region."""
    table = plugins()
    common = [p for p in table[COMMON[0]] if all(p in table[name] for name in COMMON)]
    header = "| name | type | default | meaning | flags |\n| --- | --- | --- | --- | --- |\n"
    out = {"common": header + "".join(p.markdown() + "\n" for p in common)}
    for name, params in table.items():
        own = [p for p in params if name not in COMMON or p not in common]
        out[name] = header + "".join(p.markdown() + "\n" for p in own)
    return out


def render(readme: str) -> str:
    """`readme` with every region replaced by its table."""
    for region, table in regions().items():
        pattern = re.compile(rf"(<!-- params:{region}:begin[^>]*-->\n).*?(<!-- params:{region}:end -->)", re.S)
        if not pattern.search(readme):
            raise ValueError(f"{README.name} has no region params:{region}")
        readme = pattern.sub(lambda m: m.group(1) + table + m.group(2), readme)
    return readme


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="only check that the README is current")
    args = p.parse_args()
    current = README.read_text()
    wanted = render(current)
    if not args.check:
        README.write_text(wanted)
        return 0
    if current != wanted:
        sys.stdout.writelines(difflib.unified_diff(current.splitlines(True), wanted.splitlines(True),
                                                   "plugin/README.md", "generated"))
        print("plugin/README.md is out of date: run python tools/plugin_docs.py", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

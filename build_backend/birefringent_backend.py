"""The PEP 517 build backend of the `mitsuba-birefringent` distribution (pyproject.toml).

It builds the plugin library (the Rust core and the C++ shim) against the `mitsuba`, `drjit` and
`nanobind` installed in the environment it runs in (pip's isolated build environment, with the
versions pinned in pyproject.toml's `build-system.requires`; or `.venv/` for `make setup`, which
runs `pip install --no-build-isolation -e .` and then this file as a script), and packs it with
the Python package `plugin/mitsuba_birefringent/` into a wheel:

- tag `cpXY-cpXY-<platform>` of the building interpreter: the library is bound to the binary
  interface of the `mitsuba` wheel it was compiled against, which is specific to the interpreter
  (mitsuba ships one wheel per CPython version) and to the platform; the platform tag is the
  build machine's (`linux_x86_64`), not a manylinux tag, since the library is linked against the
  build machine's C++ runtime without an audit;
- `Requires-Dist: mitsuba==<the version built against>` and the same for `drjit`;
- the version of Cargo.toml's `[package]` (the one source of the version);
- the console script of `[project.scripts]`.

The library finds libmitsuba and libdrjit-core through its RUNPATH `$ORIGIN/../mitsuba` and
`$ORIGIN/../drjit` (set by the link flags of cpp/build.rs), i.e. beside itself in site-packages.

Only the standard library is used (tomllib: Python >= 3.11).
"""

from __future__ import annotations

import base64
import hashlib
import importlib.metadata
import importlib.util
import io
import subprocess
import sys
import sysconfig
import tarfile
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The one command that builds the plugin library, against the mitsuba/drjit/nanobind packages
#: installed in the directory `{site}` (headers, libmitsuba, libdrjit-core): cargo builds the
#: crate cpp/ (cpp/build.rs compiles the shim), rebuilding when `{site}` or its wheels change.
BUILD_COMMAND = ("make", "--no-print-directory", "plugin-lib", "SITE={site}")
#: The file the build command writes (relative to the repository root).
LIBRARY = "plugin/mitsuba_birefringent/libmitsuba_birefringent.so"

#: The import package and the directory that holds it.
PACKAGE = "mitsuba_birefringent"
PACKAGE_PARENT = ROOT / "plugin"
#: The distributions whose headers and libraries the library is built against; their versions
#: become exact requirements of the wheel.
BUILT_AGAINST = ("mitsuba", "drjit")
#: Headers only (Mitsuba's headers include nanobind's).
HEADERS_ONLY = ("nanobind",)
#: What an sdist holds: everything the build command needs.
SDIST_PATHS = ("pyproject.toml", "build_backend", "Cargo.toml", "Cargo.lock", "build.rs",
               "Makefile", "requirements.txt", "README.md", "src", "cpp", "plugin")
#: [project] keys this backend implements (any other key is an error, not silently dropped).
PROJECT_KEYS = {"name", "description", "readme", "requires-python", "license", "scripts",
                "dynamic"}


def _project() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as f:
        project = tomllib.load(f)["project"]
    unknown = set(project) - PROJECT_KEYS
    if unknown:
        raise ValueError(f"pyproject.toml: [project] keys not supported by this backend: {sorted(unknown)}")
    if set(project.get("dynamic", ())) != {"version", "dependencies"}:
        raise ValueError("pyproject.toml: dynamic must be [\"version\", \"dependencies\"]")
    return project


def version() -> str:
    """The distribution's version: Cargo.toml's `[package] version`."""
    with open(ROOT / "Cargo.toml", "rb") as f:
        return tomllib.load(f)["package"]["version"]


def _site(distribution: str) -> Path:
    """The site-packages directory that holds the installed import package `distribution`."""
    spec = importlib.util.find_spec(distribution)
    if spec is None or spec.origin is None:
        raise RuntimeError(f"{distribution} is not installed in the build environment ({sys.executable})")
    return Path(spec.origin).resolve().parents[1]


def build_site() -> Path:
    """The one directory holding every package the library is compiled against."""
    sites = {name: _site(name) for name in BUILT_AGAINST + HEADERS_ONLY}
    if len(set(sites.values())) != 1:
        raise RuntimeError(f"mitsuba, drjit and nanobind must be installed in one directory, found {sites}")
    return next(iter(sites.values()))


def requirements() -> list[str]:
    """`name==version` of every distribution the library is built against, as installed here."""
    return [f"{name}=={importlib.metadata.version(name)}" for name in BUILT_AGAINST]


def build_library() -> Path:
    """Runs the build command for this interpreter's mitsuba/drjit/nanobind; returns the library."""
    command = [arg.format(site=build_site()) for arg in BUILD_COMMAND]
    subprocess.run(command, cwd=ROOT, check=True)
    library = ROOT / LIBRARY
    if not library.is_file():
        raise RuntimeError(f"the build command {command} did not write {library}")
    return library


def wheel_tag() -> str:
    """`cpXY-cpXY-<platform>` of this interpreter (see the module's docstring)."""
    if sys.implementation.name != "cpython":
        raise RuntimeError("the plugin library is built for CPython's mitsuba wheels only")
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{python}-{python}-{platform}"


def _dist_name() -> str:
    return _project()["name"].replace("-", "_")


def _dist_info() -> str:
    return f"{_dist_name()}-{version()}.dist-info"


def _metadata() -> str:
    project = _project()
    lines = ["Metadata-Version: 2.1", f"Name: {project['name']}", f"Version: {version()}",
             f"Summary: {project['description']}", f"Requires-Python: {project['requires-python']}",
             f"License: {project['license']}"]
    lines += [f"Requires-Dist: {r}" for r in requirements()]
    text = "\n".join(lines) + "\n"
    if "readme" in project:
        text += "Description-Content-Type: text/markdown\n\n" + (ROOT / project["readme"]).read_text()
    return text


def _entry_points() -> str:
    scripts = _project().get("scripts", {})
    return "[console_scripts]\n" + "".join(f"{k} = {v}\n" for k, v in scripts.items())


def _wheel_file() -> str:
    return (f"Wheel-Version: 1.0\nGenerator: {Path(__file__).name}\nRoot-Is-Purelib: false\n"
            f"Tag: {wheel_tag()}\n")


def _dist_info_files() -> dict[str, bytes]:
    info = _dist_info()
    return {f"{info}/METADATA": _metadata().encode(), f"{info}/WHEEL": _wheel_file().encode(),
            f"{info}/entry_points.txt": _entry_points().encode()}


def _package_files(library: Path) -> dict[str, bytes]:
    """The import package: its Python modules and the plugin library."""
    files = {f"{PACKAGE}/{p.name}": p.read_bytes()
             for p in sorted((PACKAGE_PARENT / PACKAGE).glob("*.py"))}
    files[f"{PACKAGE}/{library.name}"] = library.read_bytes()
    return files


def _write_wheel(directory: str, files: dict[str, bytes]) -> str:
    """Writes `files` (archive path -> content) and the RECORD into a wheel; returns its name."""
    name = f"{_dist_name()}-{version()}-{wheel_tag()}.whl"
    record_path = f"{_dist_info()}/RECORD"
    record = io.StringIO()
    with zipfile.ZipFile(Path(directory) / name, "w", zipfile.ZIP_DEFLATED) as whl:
        for path, data in files.items():
            info = zipfile.ZipInfo(path, date_time=(2020, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if path.endswith(".so") else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            whl.writestr(info, data)
            digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
            record.write(f"{path},sha256={digest},{len(data)}\n")
        record.write(f"{record_path},,\n")
        whl.writestr(record_path, record.getvalue())
    return name


def _write_metadata(directory: str) -> str:
    for path, data in _dist_info_files().items():
        target = Path(directory) / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    return _dist_info()


## ---- PEP 517 hooks ---------------------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return _write_metadata(metadata_directory)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    library = build_library()
    return _write_wheel(wheel_directory, {**_package_files(library), **_dist_info_files()})


def build_sdist(sdist_directory, config_settings=None):
    """The sources the build needs (SDIST_PATHS, without build outputs) and PKG-INFO."""
    base = f"{_dist_name()}-{version()}"
    name = f"{base}.tar.gz"
    with tarfile.open(Path(sdist_directory) / name, "w:gz") as tar:
        for entry in SDIST_PATHS:
            tar.add(ROOT / entry, arcname=f"{base}/{entry}", filter=_sdist_filter)
        pkg_info = _metadata().encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size = len(pkg_info)
        tar.addfile(info, io.BytesIO(pkg_info))
    return name


def _sdist_filter(info: tarfile.TarInfo):
    parts = Path(info.name).parts
    if "__pycache__" in parts or info.name.endswith((".so", ".pyc")):
        return None
    return info


## ---- PEP 660 hooks (editable install: `make setup`) ----------------------------------------

def get_requires_for_build_editable(config_settings=None):
    return []


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return _write_metadata(metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    """A wheel whose .pth puts plugin/ on sys.path; the library is built in place (LIBRARY)."""
    library = build_library()
    in_package = PACKAGE_PARENT / PACKAGE / library.name
    if library.resolve() != in_package.resolve():
        in_package.write_bytes(library.read_bytes())
    pth = {f"{PACKAGE}.pth": f"{PACKAGE_PARENT}\n".encode()}
    return _write_wheel(wheel_directory, {**pth, **_dist_info_files()})


if __name__ == "__main__":
    # `make plugin`: rebuild the library in place for this interpreter (after the editable
    # install), with the same command as the wheel.
    build_library()

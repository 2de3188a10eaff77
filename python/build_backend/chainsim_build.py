"""chainsim's PEP 517 build backend: `pip install .` and `pip wheel .` run the project's CMake.

pyproject.toml names this module (backend-path = python/build_backend). Debian 12 ships no scikit-build-core, so
the backend is this file, standard library only: it configures the source tree with CMake for the interpreter
that runs it (-DPython_EXECUTABLE=sys.executable), builds the targets of [tool.chainsim-build] (the executable
and the Python package), installs the components `python` and `runtime` into a staging prefix
(`cmake --install --component`: the install rules are the one list of what goes where), and packs the staging
prefix into a wheel:

    lib/pythonX.Y/site-packages/{chainsim,chainsim_plot}/   ->  the wheel's root (platlib)
    bin/chainsim                                            ->  chainsim-V.data/scripts/chainsim (pip puts it in
                                                                 the environment's bin/, beside the packages'
                                                                 lib/pythonX.Y/site-packages, where it finds them)

The CMake build directory is build/wheel-<tag>/ in the source tree (kept: a second `pip install .` rebuilds only
what changed), or the config setting `build-dir` (`pip wheel . --config-settings build-dir=/tmp/b`), or the
environment variable CHAINSIM_WHEEL_BUILD_DIR. CMAKE_BUILD_PARALLEL_LEVEL sets the build's jobs (default: every
core this process may use). Nothing is downloaded: every dependency is a Debian package (scripts/quickstart.sh).
"""
import base64
import hashlib
import os
import re
import shutil
import stat
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAME = "chainsim"


class BuildError(RuntimeError):
    """A step of the build failed: the message says which and what to install."""


def _toml(path):
    try:
        import tomllib  # Python 3.11
    except ImportError:
        try:
            import tomli as tomllib  # Debian's python3-tomli
        except ImportError:
            from pip._vendor import tomli as tomllib  # the pip that runs this backend has one
    with open(path, "rb") as fh:
        return tomllib.load(fh)


def _pyproject():
    return _toml(os.path.join(ROOT, "pyproject.toml"))


def version():
    """The version of project(chainsim VERSION ...) in CMakeLists.txt (the one place it is written)."""
    with open(os.path.join(ROOT, "CMakeLists.txt")) as fh:
        m = re.search(r"project\(\s*chainsim\s+VERSION\s+([0-9][0-9.]*)", fh.read())
    if not m:
        raise BuildError("CMakeLists.txt: no project(chainsim VERSION x.y.z)")
    return m.group(1)


def wheel_tag():
    """The tag of a wheel holding an extension module for this interpreter, e.g. cp311-cp311-linux_x86_64."""
    impl = {"cpython": "cp", "pypy": "pp"}.get(sys.implementation.name, sys.implementation.name[:2])
    python = f"{impl}{sys.version_info[0]}{sys.version_info[1]}"
    abi = python + ("d" if hasattr(sys, "gettotalrefcount") else "")
    platform = re.sub(r"[^A-Za-z0-9]", "_", sysconfig.get_platform())
    return f"{python}-{abi}-{platform}"


def _dist_info():
    return f"{NAME}-{version()}.dist-info"


def metadata_text():
    """METADATA (core metadata 2.1) from pyproject.toml's [project] and the version of CMakeLists.txt."""
    project = _pyproject()["project"]
    lines = ["Metadata-Version: 2.1", f"Name: {project['name']}", f"Version: {version()}",
             f"Summary: {project['description']}", f"Requires-Python: {project['requires-python']}",
             "License: BSD-3-Clause"]
    lines += [f"Requires-Dist: {d}" for d in project.get("dependencies", [])]
    for extra, deps in project.get("optional-dependencies", {}).items():
        lines.append(f"Provides-Extra: {extra}")
        lines += [f"Requires-Dist: {d}; extra == \"{extra}\"" for d in deps]
    readme = os.path.join(ROOT, project.get("readme", "README.md"))
    text = "\n".join(lines) + "\n"
    if os.path.exists(readme):
        with open(readme, encoding="utf-8") as fh:
            text += "Description-Content-Type: text/markdown\n\n" + fh.read()
    return text


def _wheel_text():
    return f"Wheel-Version: 1.0\nGenerator: chainsim_build\nRoot-Is-Purelib: false\nTag: {wheel_tag()}\n"


def _run(command, what):
    print("chainsim_build:", " ".join(command), flush=True)
    r = subprocess.run(command)
    if r.returncode != 0:
        raise BuildError(f"{what} failed (exit {r.returncode}): {' '.join(command)}. chainsim needs Debian's cmake, "
                         f"g++, python3-dev, pybind11-dev and the libraries of the README: bash scripts/quickstart.sh "
                         f"installs them")


def _jobs():
    if os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):
        return os.environ["CMAKE_BUILD_PARALLEL_LEVEL"]
    try:
        return str(len(os.sched_getaffinity(0)) or 1)
    except AttributeError:
        return str(os.cpu_count() or 1)


def python_dir():
    """Where the packages go under a prefix: lib/pythonX.Y/site-packages, as in a virtual environment (the
    installed `chainsim` finds them there, PREFIX/bin/../lib/pythonX.Y/site-packages: cases/cli/python_command.cpp)."""
    return f"lib/python{sys.version_info[0]}.{sys.version_info[1]}/site-packages"


def build_directory(config_settings=None):
    configured = (config_settings or {}).get("build-dir") or os.environ.get("CHAINSIM_WHEEL_BUILD_DIR")
    return os.path.abspath(configured) if configured else os.path.join(ROOT, "build", "wheel-" + wheel_tag())


def stage(prefix, config_settings=None):
    """Configures, builds and installs the wheel's components into `prefix`; returns the packages' directory."""
    if shutil.which("cmake") is None:
        raise BuildError("cmake is not installed (Debian package cmake; bash scripts/quickstart.sh installs "
                         "everything)")
    build = build_directory(config_settings)
    settings = _pyproject().get("tool", {}).get("chainsim-build", {})
    _run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DCHAINSIM_BUILD_TESTS=OFF",
          "-DCHAINSIM_PYTHON=ON", f"-DPython_EXECUTABLE={sys.executable}",
          f"-DCHAINSIM_PYTHON_INSTALL_DIR={python_dir()}"], "configuring with CMake")
    _run(["cmake", "--build", build, "-j", _jobs(), "--target",
          *settings.get("targets", ["chainsim", "chainsim_python"])], "building")
    return install(build, prefix, settings.get("components", ["python", "runtime"]))


def install(build, prefix, components=("python", "runtime")):
    """`cmake --install` of the wheel's components of the build tree `build` into `prefix`; returns the packages'
    directory (PREFIX/lib/pythonX.Y/site-packages)."""
    for component in components:
        _run(["cmake", "--install", build, "--prefix", prefix, "--component", component], f"installing {component}")
    packages = os.path.join(prefix, python_dir())
    if not any(f.startswith("_core") for f in os.listdir(os.path.join(packages, "chainsim"))):
        raise BuildError(f"the extension chainsim._core was not built for {sys.executable}: install Debian's "
                         f"python3-dev and pybind11-dev (or the headers of this interpreter), then build again")
    return packages


def _record_line(arcname, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


def _add(zf, records, arcname, data, executable=False):
    info = zipfile.ZipInfo(arcname, date_time=(2020, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = (stat.S_IFREG | (0o755 if executable else 0o644)) << 16   # pip: a regular file, +x kept
    zf.writestr(info, data)
    records.append(_record_line(arcname, data))


def _write_dist_info(directory):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "METADATA"), "w", encoding="utf-8") as fh:
        fh.write(metadata_text())
    with open(os.path.join(directory, "WHEEL"), "w") as fh:
        fh.write(_wheel_text())


# ---------------------------------------------------------------------------------------------------------------
# PEP 517 hooks

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    _write_dist_info(os.path.join(metadata_directory, _dist_info()))
    return _dist_info()


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    with tempfile.TemporaryDirectory() as prefix:
        return pack_wheel(prefix, stage(prefix, config_settings), wheel_directory)


def pack_wheel(prefix, packages, wheel_directory):
    """Packs an installed prefix into the wheel (see the module's comment); returns the wheel's file name.
    `packages`: the prefix's site-packages directory. (tests/python/test_package.py packs the test build's
    install with it.)"""
    name = f"{NAME}-{version()}-{wheel_tag()}.whl"
    data_dir = f"{NAME}-{version()}.data"
    os.makedirs(wheel_directory, exist_ok=True)
    records = []
    with zipfile.ZipFile(os.path.join(wheel_directory, name), "w") as zf:
        for top, dirs, files in os.walk(packages):
            dirs[:] = sorted(d for d in dirs if d != "__pycache__")
            for f in sorted(files):
                full = os.path.join(top, f)
                with open(full, "rb") as fh:
                    _add(zf, records, os.path.relpath(full, packages).replace(os.sep, "/"), fh.read(),
                         os.access(full, os.X_OK) and not f.endswith(".py"))
        bindir = os.path.join(prefix, "bin")
        for f in sorted(os.listdir(bindir)):
            with open(os.path.join(bindir, f), "rb") as fh:
                _add(zf, records, f"{data_dir}/scripts/{f}", fh.read(), executable=True)
        info = _dist_info()
        _add(zf, records, f"{info}/METADATA", metadata_text().encode("utf-8"))
        _add(zf, records, f"{info}/WHEEL", _wheel_text().encode())
        with open(os.path.join(ROOT, "LICENSE"), "rb") as fh:
            _add(zf, records, f"{info}/LICENSE", fh.read())
        records.append(f"{info}/RECORD,,")
        zf.writestr(zipfile.ZipInfo(f"{info}/RECORD", date_time=(2020, 1, 1, 0, 0, 0)), "\n".join(records) + "\n")
    return name


def build_sdist(sdist_directory, config_settings=None):
    """The source tree as NAME-VERSION.tar.gz: every file but build trees, results and version control."""
    base = f"{NAME}-{version()}"
    skip = {".git", "build", "results", "out", "__pycache__", ".pytest_cache", ".mypy_cache", ".cache"}
    os.makedirs(sdist_directory, exist_ok=True)
    path = os.path.join(sdist_directory, base + ".tar.gz")
    with tarfile.open(path, "w:gz", format=tarfile.PAX_FORMAT) as tar:
        for top, dirs, files in os.walk(ROOT):
            dirs[:] = sorted(d for d in dirs if d not in skip and not d.startswith("build-"))
            for f in sorted(files):
                full = os.path.join(top, f)
                tar.add(full, arcname=os.path.join(base, os.path.relpath(full, ROOT)), recursive=False)
        info = tarfile.TarInfo(os.path.join(base, "PKG-INFO"))
        data = metadata_text().encode("utf-8")
        info.size = len(data)
        import io
        tar.addfile(info, io.BytesIO(data))
    return os.path.basename(path)

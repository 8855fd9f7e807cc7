"""The Python package as `cmake --install` puts it (ctest python.installed): run by the interpreter the module was
built for, with PYTHONPATH set to the installed site directory only.

    python_installed.py SITE_DIR RELATIVE_SITE_DIR DEFAULT_PREFIX

Checks that `import tethash` loads the installed package (not the build tree's) and detects; that the relative site
directory under CMake's default prefix is one this interpreter searches (so a default `cmake --install` needs no
PYTHONPATH); and that the package under an interpreter of another version says so instead of failing obscurely.
"""

import os
import shutil
import site
import subprocess
import sys
import tempfile

import numpy as np

site_dir, relative_site, default_prefix = sys.argv[1:4]
site_dir = os.path.realpath(site_dir)

import tethash  # noqa: E402

package = os.path.realpath(os.path.dirname(tethash.__file__))
assert package == os.path.join(site_dir, "tethash"), f"imported {package}, not the installed {site_dir}/tethash"

# Two unit tets, vertex 7 inside tet 0.
positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1],
                      [5, 5, 5], [6, 5, 5], [5, 6, 5], [0.1, 0.1, 0.1]], dtype=np.float64)
tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]], dtype=np.int32)
contacts = tethash.detect(positions, tets, vertex_object=np.array([0, 0, 0, 0, 1, 1, 1, 1]),
                          tet_object=np.array([0, 1]))
assert [(c["vertex"], c["tet"]) for c in contacts] == [(7, 0)], contacts

# A default install (prefix /usr/local) lands where this interpreter looks.
searched = [os.path.realpath(p) for p in site.getsitepackages()]
default_site = os.path.realpath(os.path.join(default_prefix, relative_site))
assert default_site in searched, f"{default_site} is not among this interpreter's site directories {searched}"

# The installed package copied, its compiled module renamed as if built for Python 3.99: the import must name both
# versions and the interpreter to use.
with tempfile.TemporaryDirectory() as tmp:
    copy = os.path.join(tmp, "tethash")
    shutil.copytree(package, copy, ignore=shutil.ignore_patterns("__pycache__"))
    for name in os.listdir(copy):
        if name.startswith("_tethash."):
            os.rename(os.path.join(copy, name), os.path.join(copy, "_tethash.cpython-399-x86_64-linux-gnu.so"))
    with open(os.path.join(copy, "_build_info.py"), "w", encoding="utf-8") as f:
        f.write('PYTHON = "/opt/python3.99/bin/python3"\nPYTHON_VERSION = (3, 99)\n')
    env = dict(os.environ, PYTHONPATH=tmp, PYTHONDONTWRITEBYTECODE="1")
    run = subprocess.run([sys.executable, "-c", "import tethash"], env=env, capture_output=True, text=True,
                         check=False)
    assert run.returncode != 0, "the mismatched package imported"
    here = f"Python {sys.version_info[0]}.{sys.version_info[1]} ({sys.executable})"
    for part in ("this build of the module is for Python 3.99 (/opt/python3.99/bin/python3)", here,
                 "-DPython3_EXECUTABLE="):
        assert part in run.stderr, f"'{part}' missing from:\n{run.stderr}"
    assert "initialization failed" not in run.stderr, run.stderr

print(f"python.installed: tethash from {package}; default install into {default_site}, searched by {sys.executable}")

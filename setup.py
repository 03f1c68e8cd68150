"""The build step that compiles the decode kernels at install time (see bistair/app/kernels.py).

Everything else about the package is in pyproject.toml. After the Python files are in place
(the build folder, or the source tree for an editable install), the numba kernels listed in
``src/bistair/app/kernels.txt`` are compiled into ``bistair/_kernels`` on every core, so that
the first decode loads them instead of compiling them (about a minute on two cores). Set
``BISTAIR_NO_PREBUILD=1`` to skip it: the kernels then compile on their first call. A
failure here never fails the install.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildWithKernels(build_py):
    def run(self) -> None:
        super().run()
        if os.environ.get("BISTAIR_NO_PREBUILD"):
            return
        root = Path("src").resolve() if getattr(self, "editable_mode", False) \
            else Path(self.build_lib).resolve()
        folder = root / "bistair" / "_kernels"
        # the package first, then what pip's isolated build environment puts on the path
        # (numpy and numba of [build-system] requires: the new environment has none yet)
        path = [str(root), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(path)}
        env.pop("BISTAIR_KERNELS", None)
        print(f"compiling the decode kernels into {folder} (BISTAIR_NO_PREBUILD=1 skips it)",
              flush=True)
        try:
            subprocess.run([sys.executable, "-m", "bistair.app.kernels", str(folder)],
                           env=env, check=True, cwd=str(root))
        except (OSError, subprocess.CalledProcessError) as exc:
            print(f"warning: the kernels were not all compiled ({exc}): they compile on "
                  "their first call", file=sys.stderr)


setup(cmdclass={"build_py": BuildWithKernels})

"""OpenBLAS kernels for the portability step of .ci/run.

``python .ci/blas_kernel.py`` prints a kernel other than the one this machine loads (empty
where the processor family has no second kernel to name). ``python .ci/blas_kernel.py
check NAME`` fails unless every OpenBLAS that NumPy and SciPy load reports NAME, so that
setting ``OPENBLAS_CORETYPE`` is seen to take effect (an unknown name falls back silently).
"""

import platform
import sys

import numpy  # noqa: F401  (loads NumPy's OpenBLAS)
import scipy.linalg  # noqa: F401  (loads SciPy's)
from threadpoolctl import threadpool_info

# Sandybridge has AVX but no FMA: its dot products and factorizations round differently
# from the Haswell, Zen and SkylakeX kernels a current x86 processor selects.
ALTERNATIVES = {"x86_64": ("Sandybridge", "Nehalem"), "aarch64": ("ARMV8", "NeoverseN1")}


def loaded() -> set[str]:
    return {str(i.get("architecture")).lower() for i in threadpool_info()
            if i.get("internal_api") == "openblas"}


def main(argv: list[str]) -> int:
    now = loaded()
    if argv[:1] == ["check"]:
        if now != {argv[1].lower()}:
            print(f"OpenBLAS kernels loaded: {sorted(now) or 'none'}; expected {argv[1]}",
                  file=sys.stderr)
            return 1
        return 0
    for name in ALTERNATIVES.get(platform.machine(), ()):
        if now and name.lower() not in now:
            print(name)
            break
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

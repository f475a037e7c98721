"""What every test process shares: numba's boxing module imported whole before any test runs.

numba imports `numba.core.boxing` lazily, the first time a process compiles a kernel's Python
wrapper. CI fills the kernel cache before its two test workers start, so a worker's first compile
comes late, in whichever test needs a kernel the cache lacks; once, a worker's import of it was
left half done and every later compile in that worker failed with "duplicate registration for
Boolean". Imported here it is whole from the start.
"""

import numba.core.boxing  # noqa: F401

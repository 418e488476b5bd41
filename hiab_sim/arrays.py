"""The array type every numeric module annotates with: float64 samples in SI units.

One alias for the whole package (``Array``), so that a signature reads the same in every module; the
unit and shape of each array are stated in the docstring of the function that takes it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

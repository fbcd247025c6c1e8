"""Type hints of the native module (``python/src/lib.rs``); use the ``tetcdt`` package."""

import os
from typing import Any, Optional, Union

import numpy as np
import numpy.typing as npt

class InvalidInputError(ValueError):
    """The input is not a valid PLC (the command line's exit code 3)."""

class MeshingError(RuntimeError):
    """Meshing failed on a valid input (the command line's exit code 1)."""

class MeshFiles:
    """The part of a mesh that its arrays do not hold, for writing TetGen's files."""

    def write(
        self,
        prefix: Union[str, os.PathLike[str]],
        points: npt.NDArray[np.float64],
        tets: npt.NDArray[np.int32],
    ) -> list[str]: ...

class Plc:
    """A PLC read from a file."""

    points: npt.NDArray[np.float64]
    facet_arrays: tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.int64]]
    facet_markers: npt.NDArray[np.int64]
    facet_holes: list[list[tuple[float, float, float]]]
    holes: npt.NDArray[np.float64]
    regions: npt.NDArray[np.float64]
    first_index: int
    source: str
    warnings: list[str]
    def tetrahedralize(self, switches: str) -> dict[str, Any]: ...

def tetrahedralize(
    points: npt.NDArray[np.float64],
    indices: npt.NDArray[np.int64],
    polygon_ends: npt.NDArray[np.int64],
    facet_ends: npt.NDArray[np.int64],
    facet_markers: Optional[npt.NDArray[np.int64]],
    holes: Optional[npt.NDArray[np.float64]],
    regions: Optional[npt.NDArray[np.float64]],
    switches: str,
) -> dict[str, Any]: ...
def read(path: Union[str, os.PathLike[str]]) -> Plc: ...

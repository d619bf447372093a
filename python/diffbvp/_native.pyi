"""Type stubs of the Rust layer ``diffbvp._native`` (use the ``diffbvp`` package instead)."""

from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

_Arrays = Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]

class Dataset:
    @staticmethod
    def load(path: str) -> "Dataset": ...
    @staticmethod
    def from_toml(text: str, path: str, measurements: Optional[Mapping[str, _Arrays]] = None) -> "Dataset": ...
    @staticmethod
    def from_conditions(conditions: Mapping[str, Any], measurements: Optional[Mapping[str, _Arrays]] = None) -> "Dataset": ...
    @property
    def path(self) -> str: ...
    @property
    def toml(self) -> str: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def relative_uncertainty(self) -> Optional[float]: ...
    def measurements(self) -> Dict[str, _Arrays]: ...
    def conditions(self) -> List[Dict[str, Any]]: ...
    def __len__(self) -> int: ...

def fit(dataset: Dataset, *, start: Optional[Tuple[float, float]] = None, estimator: str = "principled",
        model: Optional[str] = None, effects: Sequence[str] = ..., loss: str = "linear",
        f_scale: Optional[float] = None, relative_uncertainty: Optional[float] = None,
        error_budget: bool = True, tol: Optional[float] = None, max_nodes: Optional[int] = None,
        profile_points: int = 101, start_from: Optional[str] = None) -> Dict[str, Any]:
    """{"summary": FitSummary dict, "text": str, "arrays": {"residual_profiles", "profiles"},
    "notes": [str]}"""
def simulate(dataset: Dataset, n: float = 0.8, kappa: float = 11.71, *, effects: Sequence[str] = ...,
             take_up_diameter: Optional[float] = None, take_up_from_data: bool = False,
             points: int = 101, positions: Optional[Sequence[float]] = None,
             sensitivities: bool = False, tol: Optional[float] = None,
             max_nodes: Optional[int] = None) -> Dict[str, Any]: ...
def compare(dataset: Dataset, fit: Optional[Mapping[str, Any]] = None, *, n: Optional[float] = None,
            kappa: Optional[float] = None, newtonian: bool = False, take_up_from_data: bool = False,
            effects: Sequence[str] = ..., relative_uncertainty: Optional[float] = None,
            tol: Optional[float] = None, max_nodes: Optional[int] = None) -> Dict[str, Any]:
    """{"comparison": Comparison dict, "text": str}"""
def diagnose(dataset: Dataset, *, model: Optional[str] = None, effects: Sequence[str] = ...,
             candidates: Optional[Sequence[str]] = None, refit_top: Optional[int] = None,
             start: Optional[Tuple[float, float]] = None, tol: Optional[float] = None,
             max_nodes: Optional[int] = None, start_from: Optional[str] = None) -> Dict[str, Any]:
    """{"diagnosis": Diagnosis dict, "text": str, "base_arrays": {"residual_profiles"},
    "final_arrays": {"residual_profiles"} | None}"""
def landscape(dataset: Dataset, *, grid: Tuple[int, int] = (41, 41),
              n_range: Tuple[float, float] = (0.0, 1.0), kappa_range: Tuple[float, float] = (9.0, 16.0),
              estimator: str = "paper", tol: float = 1e-4,
              max_nodes: Optional[int] = None, uniform_tol: bool = False) -> Dict[str, Any]: ...
def library_version() -> str: ...
def set_threads(n: Optional[int] = None) -> None: ...
def threads() -> int: ...

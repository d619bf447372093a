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
def simulate(dataset: Dataset, n: float, kappa: float, *, effects: Sequence[str] = ...,
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
def design(dataset: Dataset, *, template: Optional[str] = None,
           mass_flow: Optional[Tuple[float, float]] = None,
           stencil_velocity: Optional[Tuple[float, float]] = None,
           take_up_diameter: Optional[Tuple[float, float]] = None,
           take_up_velocity: Optional[Tuple[float, float]] = None,
           grid: Tuple[int, int] = (9, 9), criterion: str = "d",
           discriminate: Optional[Sequence[str]] = None,
           start: Optional[Tuple[float, float]] = None, noise: Optional[float] = None,
           tol: float = 1e-6, max_nodes: Optional[int] = None) -> Dict[str, Any]: ...
def library_version() -> str: ...
def set_threads(n: Optional[int] = None) -> None: ...
def threads() -> int: ...

class ExprProblem:
    """A BVP given as expressions (used by ``diffbvp.solve_bvp``): ``fun`` one expression per
    state, ``bc`` one per boundary residual (n + k), the names of the unknowns and of the model
    parameters, named constants, an optional singular term (n × n, row-major)."""

    def __init__(self, fun: List[str], bc: List[str], unknowns: List[str], params: List[str],
                 constants: List[Tuple[str, float]], singular: Optional[List[float]] = None) -> None: ...
    @property
    def n(self) -> int: ...
    @property
    def k(self) -> int: ...
    @property
    def q(self) -> int: ...
    @property
    def fun(self) -> List[str]: ...
    @property
    def bc(self) -> List[str]: ...
    def rhs(self, x: List[float], y: np.ndarray, p: List[float]) -> np.ndarray: ...
    def solve(self, x: List[float], y: np.ndarray, unknowns: List[float], params: List[float],
              tol: float, bc_tol: Optional[float], max_nodes: int, verbose: int,
              scipy_mesh: bool) -> Tuple[int, str, Optional["BvpSolution"]]: ...
    def fit(self, x: List[float], y: np.ndarray, unknowns: List[float], params: List[float],
            fit: List[int], lower: List[float], upper: List[float], data_x: List[float],
            data_y: List[float], sigma: List[float], component: int, tol: float,
            max_nodes: int, xtol: float, ftol: float, max_iterations: int
            ) -> Tuple[List[float], float, List[float], List[float], str, bool, int, int,
                       "BvpSolution"]: ...

class BvpSolution:
    """A converged solution of an ``ExprProblem`` with its derivatives."""

    @property
    def x(self) -> np.ndarray: ...
    @property
    def y(self) -> np.ndarray: ...
    @property
    def yp(self) -> np.ndarray: ...
    @property
    def unknowns(self) -> np.ndarray: ...
    @property
    def rms_residuals(self) -> np.ndarray: ...
    @property
    def stats(self) -> Tuple[int, int, int, float, float]: ...
    def eval(self, xs: List[float], nu: int) -> np.ndarray: ...
    def sensitivities(self, xs: Optional[List[float]] = None) -> Tuple[np.ndarray, np.ndarray]: ...
    def adjoint_gradient(self, functional: str, xs: List[float],
                         weights: List[float]) -> Tuple[float, np.ndarray]: ...
    def integral(self, integrand: str,
                 endpoint: Optional[str] = None) -> Tuple[float, np.ndarray]: ...

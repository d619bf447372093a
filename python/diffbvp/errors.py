"""Exceptions raised by :mod:`diffbvp`.

Every exception carries the message the ``rheometer`` command-line program prints for the same
problem: file, line, table and key of a bad input; the experiment, its TOML line and likely
causes (``hint:`` lines) of a failed simulation.
"""

from __future__ import annotations

from typing import List, Optional

__all__ = ["DiffbvpError", "InputError", "SimulationError", "FitError", "EvaluationError"]


class DiffbvpError(Exception):
    """Base class of the errors of :mod:`diffbvp`.

    Attributes set where known (``None`` otherwise):

    * ``experiment``: the experiment whose simulation failed;
    * ``path``: the experiments file;
    * ``line``: the 1-based line of the experiment's ``name`` key;
    * ``hints``: likely causes of a failed simulation, in words.
    """

    experiment: Optional[str] = None
    path: Optional[str] = None
    line: Optional[int] = None
    hints: List[str] = []


class InputError(DiffbvpError, ValueError):
    """A bad input: a missing or malformed file, an implausible value, a bad argument.

    The message names the file and line (``experiments.toml:23: ...``), the table and key, or
    the argument and its allowed range.
    """


class SimulationError(DiffbvpError):
    """A simulation that failed (no solution of the fiber BVP), naming the experiment, its
    TOML line, the law parameters and likely causes."""


class FitError(DiffbvpError):
    """A fit that could not run or finish (e.g. the model cannot be evaluated at the start
    point)."""


class EvaluationError(DiffbvpError, ArithmeticError):
    """A problem's right-hand side or boundary condition (an expression or a Python callable
    of :func:`diffbvp.solve_bvp`) that gave a non-finite value, raised, or returned the wrong
    shape during a solve. The message names the component (``fun[1] = "..."``), the position
    ``x`` and what to check."""

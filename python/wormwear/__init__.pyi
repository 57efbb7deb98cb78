"""Type stubs of the wormwear package (see the module's docstrings for units)."""

import os
import types
from typing import Any, Callable, Mapping, Optional, Sequence

import numpy as np
import pandas as pd

from ._native import ComputationError as ComputationError
from ._native import InputError as InputError

__version__: str
STAGES: tuple[str, ...]

class GearSet:
    @classmethod
    def from_dict(cls, document: Mapping[str, Any], *, name: str = ...) -> GearSet: ...
    def with_(self, **changes: Any) -> GearSet: ...
    def to_dict(self) -> dict: ...
    def to_toml(self) -> str: ...
    def validated(self) -> dict: ...
    @property
    def title(self) -> str: ...
    @property
    def file(self) -> str: ...

def load(path: str | os.PathLike[str]) -> GearSet: ...
def load_rexs(path: str | os.PathLike[str], stage: Optional[int] = None) -> GearSet: ...
def rexs_stages(path: str | os.PathLike[str]) -> list[dict[str, Any]]: ...

class FlankMap:
    """values[i, j] (unit ``unit``) at r_mm[i, j], z_mm[i, j] on the loaded wheel flank."""
    name: str
    unit: str
    values: np.ndarray
    r_mm: np.ndarray
    z_mm: np.ndarray

class Results:
    summary: dict
    stages: list[str]
    warnings: list[str]
    geometry: Optional[types.SimpleNamespace]
    tca: Optional[types.SimpleNamespace]
    #: ltca section values (max_pressure_pa, contact_area_fraction, te_p2p_rad, ...) and
    #: positions / pressures (DataFrame), pattern (FlankMap, Pa).
    ltca: Optional[types.SimpleNamespace]
    #: wear section values and records / positions / nodes (DataFrame), depth (FlankMap, m).
    wear: Optional[types.SimpleNamespace]
    #: friction section values (efficiency, oil temperature, MODEL §13) and table (DataFrame),
    #: coefficient / power_density (FlankMap, 1 and W/m^2).
    friction: Optional[types.SimpleNamespace]
    #: with a load spectrum (MODEL §14): the duty_cycle section values and bins (DataFrame).
    duty_cycle: Optional[types.SimpleNamespace]
    #: the standard's ratings and safety (DataFrame: the safety table from the model).
    rating: Optional[types.SimpleNamespace]
    def table(self, name: str) -> Optional[pd.DataFrame]: ...
    def to_rexs(self, path: str | os.PathLike[str]) -> None: ...
    def write(self, directory: str | os.PathLike[str]) -> list[str]: ...

def run(
    gear: GearSet,
    stages: Optional[Sequence[str]] = None,
    *,
    cycles: Optional[float] = None,
    step_cycles: Optional[float] = None,
    step_wear_um: Optional[float] = None,
    no_pitting: bool = False,
    map_position: int = 0,
    progress: Optional[Callable[[str, dict], None]] = None,
    step: bool = False,
    step_teeth: Optional[int] = None,
    step_state: Optional[int] = None,
) -> Results: ...
def sweep(
    base: GearSet,
    grid: Optional[Mapping[str, Sequence[Any]]] = None,
    *,
    cases: Optional[Sequence[Mapping[str, Any]]] = None,
    stages: Optional[Sequence[str]] = None,
    cycles: Optional[float] = None,
    step_cycles: Optional[float] = None,
    step_wear_um: Optional[float] = None,
    no_pitting: bool = False,
    output: str | os.PathLike[str] | None = None,
    client: Any = None,
) -> pd.DataFrame: ...
class Spread:
    directory: str
    reused: int
    summary: dict
    samples: pd.DataFrame
    percentiles: pd.DataFrame
    rank_correlation: pd.DataFrame
    sobol_indices: Optional[pd.DataFrame]

def spread(
    base: GearSet,
    inputs: Mapping[str, Any],
    *,
    samples: int = 64,
    seed: int = 1,
    sampler: str = "latin-hypercube",
    fixed: Optional[Mapping[str, Any]] = None,
    stages: Optional[Sequence[str]] = None,
    cycles: Optional[float] = None,
    step_cycles: Optional[float] = None,
    step_wear_um: Optional[float] = None,
    no_pitting: bool = False,
    output: str | os.PathLike[str],
    client: Any = None,
) -> Spread: ...
class Pattern:
    directory: str
    summary: dict
    settings: pd.DataFrame
    before: dict
    after: dict
    objective: dict
    path: pd.DataFrame
    gear: GearSet

def pattern(
    base: GearSet,
    target: Mapping[str, float],
    *,
    vary: Optional[Mapping[str, Sequence[float]]] = None,
    loaded: bool = False,
    evaluations: int = 60,
    output: str | os.PathLike[str],
) -> Pattern: ...
def forget_kept_sector() -> None: ...
def compare(runs: Sequence[str | os.PathLike[str]], output: str | os.PathLike[str]) -> pd.DataFrame: ...

"""wormwear — loaded contact and wear of steel-worm / bronze-wheel worm gears, from Python.

The computation is the Rust library's (the ``wormwear`` command line calls the same runner);
this package holds gears and results and hands them out in Python's habits: results'
tables are pandas DataFrames, maps are numpy arrays on their (r, z) grids, sections are
attribute namespaces. Units are SI inside, and every name says its unit
(``max_pressure_pa``, ``backlash_increase_m``); gear documents use the file's names
(``worm_torque_nm``, ``module_mm``).

    >>> import wormwear
    >>> gear = wormwear.load("examples/gear-1x40-design.toml")
    >>> heavy = gear.with_(**{"conditions.worm_torque_nm": 90.0})
    >>> r = wormwear.run(heavy, stages=["ltca"])
    >>> r.ltca.max_pressure_pa, r.ltca.positions.head()
    >>> r.write("out/heavy")                     # the files of `wormwear ltca`

Design studies: :func:`sweep` runs variants on the local cores, or on a Dask cluster when
given a ``dask.distributed.Client``.
"""

from __future__ import annotations

import json
import math
import os
import types
import warnings
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence

import numpy as np
import pandas as pd

from . import _native
from ._native import ComputationError, InputError

__version__ = _native.__version__

__all__ = [
    "GearSet",
    "Results",
    "FlankMap",
    "compare",
    "InputError",
    "ComputationError",
    "load",
    "load_rexs",
    "rexs_stages",
    "run",
    "sweep",
    "spread",
    "Spread",
    "pattern",
    "Pattern",
    "forget_kept_sector",
    "STAGES",
]

#: The pipeline's stages, in order. Each runs the ones it needs first.
STAGES = ("geometry", "tca", "ltca", "wear", "report")


class GearSet:
    """A validated gear set (worm, hob, wheel, materials, lubricant, conditions, analysis).

    Build one with :func:`load` or :meth:`from_dict`; derive variants with :meth:`with_`.
    Immutable; picklable (a Dask task carries it as its source text).
    """

    __slots__ = ("_native",)

    def __init__(self, native: "_native.NativeGear"):
        self._native = native

    @classmethod
    def from_dict(cls, document: Mapping[str, Any], *, name: str = "<dict>") -> "GearSet":
        """A gear from a document with the gear file's tables and names (units in the names:
        ``{"worm": {"lead_mm": 15.551, ...}, "conditions": {"worm_torque_nm": 60.0}, ...}``).
        Validated as the file would be: raises :class:`InputError` listing every problem."""
        return cls(_native.NativeGear.from_json(json.dumps(document, allow_nan=True), name))

    def with_(self, **changes: Any) -> "GearSet":
        """The same gear with fields changed by dotted name, validated::

            gear.with_(**{"conditions.worm_torque_nm": 50, "lubricant.temperature_c": 70})

        A value of None removes the field (it takes its default)."""
        for name, value in changes.items():
            if isinstance(value, float) and not math.isfinite(value):
                raise InputError(f"with_({name}): {value} is not a finite number")
        return GearSet(self._native.with_changes(json.dumps(changes, allow_nan=True)))

    def to_dict(self) -> dict:
        """The gear document (the file's tables and names)."""
        return json.loads(self._native.document_json())

    def to_toml(self) -> str:
        """The gear file's text: the file as read, or the document of a variant (a gear
        file the CLI reads as the same gear)."""
        return self._native.source()[1]

    def validated(self) -> dict:
        """The validated gear set in SI units, with the derived defaults filled in."""
        return json.loads(self._native.validated_json())

    @property
    def title(self) -> str:
        """The gear file's title."""
        return self._native.title

    @property
    def file(self) -> str:
        """The file the gear was read from (or a label: ``<dict>``, ``FILE with ...``)."""
        return self._native.source()[0]

    def __reduce__(self):
        file, text = self._native.source()
        return (_from_text, (text, file))

    def __repr__(self) -> str:
        return f"GearSet({self.title!r}, file={self.file!r})"


def _from_text(text: str, file: str) -> GearSet:
    return GearSet(_native.NativeGear.from_text_(text, file))


def load(path: "str | os.PathLike[str]") -> GearSet:
    """Reads and validates a gear file (TOML, the CLI's format). Raises :class:`InputError`
    (every problem with its field, value and range) or OSError."""
    return GearSet(_native.NativeGear.load(os.fspath(path)))


def compare(
    runs: Sequence["str | os.PathLike[str]"], output: "str | os.PathLike[str]"
) -> pd.DataFrame:
    """Compares finished runs (output directories of ``wormwear run``, ``ltca``, ``wear``,
    ``rating`` or ``Results.write``), as ``wormwear compare`` does: writes compare.html (the
    key results side by side with the differences to the first run, the backlash and wear
    curves overlaid), compare.csv and the curves into ``output``, and returns the key results
    as a DataFrame indexed by quantity, with a ``unit`` column and one column per run (labelled
    by its directory's name)."""
    if isinstance(runs, (str, bytes, os.PathLike)):
        raise TypeError(
            f"compare: runs must be a list of run directories, got the single path {runs!r}"
        )
    _page, labels, rows = _native.compare([os.fspath(r) for r in runs], os.fspath(output))
    frame = pd.DataFrame(
        [[unit] + [np.nan if v is None else v for v in values] for _, unit, values in rows],
        index=pd.Index([q for q, _, _ in rows], name="quantity"),
        columns=["unit"] + list(labels),
    )
    return frame


def rexs_stages(path: "str | os.PathLike[str]") -> list:
    """The worm stages of a REXS file (``.rexs`` XML, ``.rexsj`` JSON, ``.rexsz`` zip) as
    dicts with their component ``id``, ``name`` and the ``worm`` and ``wheel`` ids."""
    return [
        {"id": i, "name": n, "worm": w, "wheel": h}
        for i, n, w, h in _native.rexs_stages(os.fspath(path))
    ]


def load_rexs(path: "str | os.PathLike[str]", stage: Optional[int] = None) -> GearSet:
    """A worm stage of a REXS file as a validated gear, mapped as ``wormwear import`` maps it
    (README, "REXS"); ``stage`` is the worm stage's component id, needed when the file has
    several. The importer's warnings (a wheel material that is not a bronze, values that
    disagree) are issued as :class:`UserWarning`; ``gear.to_toml()`` is the commented gear
    file. Raises :class:`InputError` for a file that cannot be read or mapped."""
    text, notes = _native.import_rexs(os.fspath(path), stage)
    for note in notes:
        warnings.warn(f"REXS import: {note}", UserWarning, stacklevel=2)
    return _from_text(text, os.fspath(path))


class FlankMap:
    """A field over the loaded wheel flank: ``values[i, j]`` at radius ``r_mm[i, j]`` and face
    coordinate ``z_mm[i, j]`` (i up the tooth height, j across the face width)."""

    def __init__(self, name: str, unit: str, values: np.ndarray, r_mm: np.ndarray, z_mm: np.ndarray):
        self.name, self.unit = name, unit
        self.values, self.r_mm, self.z_mm = values, r_mm, z_mm

    @classmethod
    def _from_table(cls, table: pd.DataFrame, column: str, unit: str) -> "FlankMap":
        i = table["i"].to_numpy().astype(int)
        j = table["j"].to_numpy().astype(int)
        shape = (i.max() + 1, j.max() + 1)
        grids = []
        for c in (column, "r_mm", "z_mm"):
            a = np.full(shape, np.nan)
            a[i, j] = table[c].to_numpy()
            grids.append(a)
        return cls(column, unit, *grids)

    def __repr__(self) -> str:
        return f"FlankMap({self.name!r}, {self.values.shape[0]} x {self.values.shape[1]}, {self.unit})"


def _namespace(section: Optional[dict], **extra: Any) -> Optional[types.SimpleNamespace]:
    if section is None:
        return None
    ns = types.SimpleNamespace(**section)
    for k, v in extra.items():
        setattr(ns, k, v)
    return ns


def _safety_frame(table: dict) -> pd.DataFrame:
    """The safety table of summary.json as a DataFrame, the verdicts as text."""
    def verdict(v: Any) -> str:
        if isinstance(v, dict):
            return "; ".join(f"{k.replace('_', ' ')}: {t}" for k, t in v.items())
        return "FAIL" if v == "fail" else str(v)

    rows = [dict(r, verdict=verdict(r["verdict"])) for r in table["rows"]]
    frame = pd.DataFrame.from_records(rows)
    for c in ("value", "allowable", "safety", "minimum"):
        frame[c] = pd.to_numeric(frame[c], errors="coerce")
    frame.attrs["application_factor"] = table["application_factor"]
    frame.attrs["required_cycles"] = table["required_cycles"]
    return frame


class Results:
    """What a run computed, by stage (None where the stage did not run).

    - ``summary``: summary.json's sections (dict);
    - ``geometry``: derived geometry (lead angle, radii, flank area...);
    - ``tca``: unloaded analysis (kinematic error, pattern, sliding speeds);
    - ``ltca``: the ``ltca`` section's values (``max_pressure_pa``, ``contact_area_fraction``,
      ``te_p2p_rad``, ``power_balance``...) and the DataFrames ``positions`` (per position:
      torques N m, TE rad, stiffness, tooth loads N), ``pressures`` (every loaded cell:
      position, tooth, r_mm, z_mm, pressure_pa, equivalent_pressure_pa and
      equivalent_depth_mm below it, MODEL §8.1), the map ``pattern`` (largest pressure over the
      cycle, Pa) and the map ``equivalent`` (largest equivalent pressure below the flank, Pa);
    - ``wear``: the ``wear`` section's values and the DataFrames ``records`` (one row per
      state: cycles, max_wear_m, backlash_increase_m, max_pressure_pa, ...), ``positions``
      (TE and loads per state and position) and the map ``depth`` (wear depth at the end, m);
    - ``friction``: the ``friction`` section's values (friction, efficiency, oil temperature
      from the contact, MODEL §13), the DataFrame ``table`` (every flank cell: r_mm, z_mm,
      friction_coefficient, friction_power_density_w_m2) and the maps ``coefficient``
      (load-weighted friction coefficient over the cycle) and ``power_density`` (W/m^2);
    - ``duty_cycle``: with a load spectrum (``[[duty_cycle]]``, MODEL §14), the
      ``duty_cycle`` section's values (efficiencies over the energy, Miner's first pit, the
      largest-load and hottest bins) and the DataFrame ``bins`` (one row per bin: torques,
      speed, time and cycle shares, oil temperature, powers, efficiencies, pressures, wear
      per cycle, shares of the wear and of the pitting damage); None for one operating point;
    - ``rating``: the standard's ratings (efficiency, sigma_Hm, lives...) and ``safety``, the
      safety table from the model (MODEL §9.1) as a DataFrame: one row per quantity (quantity,
      symbol, unit, value, allowable, safety, minimum, verdict, source; ``attrs`` holds
      ``application_factor`` and ``required_cycles``);
    - ``warnings``: list of str.

    ``write(directory)`` writes the files the CLI writes for the same stages.
    """

    def __init__(self, native: "_native.NativeResults"):
        self._native = native
        self.summary: dict = json.loads(native.summary_json())
        self.stages: list = native.stages()
        self.warnings: list = native.warnings()
        self.geometry = _namespace(self.summary.get("geometry"))
        self.tca = _namespace(self.summary.get("tca"))
        rating = self.summary.get("rating")
        self.rating = None
        if rating is not None:
            table = rating.get("safety")
            self.rating = _namespace(rating, safety=None if table is None else _safety_frame(table))
        friction = self.summary.get("friction")
        self.friction = None
        if friction is not None:
            table = self.table("friction_map")
            self.friction = _namespace(
                friction,
                table=table,
                coefficient=FlankMap._from_table(table, "friction_coefficient", "1"),
                power_density=FlankMap._from_table(table, "friction_power_density_w_m2", "W/m^2"),
            )
        duty = self.summary.get("duty_cycle")
        self.duty_cycle = None
        if duty is not None:
            self.duty_cycle = _namespace(
                {k: v for k, v in duty.items() if k != "bins"}, bins=self.table("duty_cycle")
            )
        ltca = self.summary.get("ltca")
        self.ltca = None
        if ltca is not None:
            pattern = self.table("ltca_pattern")
            self.ltca = _namespace(
                ltca,
                positions=self.table("ltca_positions"),
                pressures=self.table("ltca_pressures"),
                pattern=FlankMap._from_table(pattern, "max_pressure_pa", "Pa"),
                equivalent=FlankMap._from_table(pattern, "equivalent_pressure_pa", "Pa"),
            )
        wear = self.summary.get("wear")
        self.wear = None
        if wear is not None:
            nodes = self.table("wear_map")
            self.wear = _namespace(
                wear,
                records=self.table("wear_steps"),
                positions=self.table("wear_positions"),
                depth=FlankMap._from_table(nodes, "wear_m", "m"),
                nodes=nodes,
            )

    def table(self, name: str) -> Optional[pd.DataFrame]:
        """A table by its file's name without ``.csv`` (ltca_positions, ltca_pattern,
        ltca_pressures, friction_map, duty_cycle, wear_steps, wear_positions, wear_map), at full precision (the files
        round to 11 digits); None if its stage did not run."""
        got = self._native.table(name)
        if got is None:
            return None
        header, columns = got
        frame = pd.DataFrame({h: np.asarray(c, dtype=float) for h, c in zip(header, columns)})
        for h in header:  # indices and counts as integers, as in the files
            col = frame[h]
            if len(col) and np.all(np.isfinite(col)) and np.all(col == np.round(col)) and (
                h in ("i", "j", "position", "tooth", "slice", "column", "step", "substeps", "loaded_analyses", "bin")
            ):
                frame[h] = col.astype(np.int64)
        return frame

    def to_rexs(self, path: "str | os.PathLike[str]") -> None:
        """Writes the stage and these results as REXS, as ``wormwear export-rexs`` does:
        JSON for a ``.rexsj`` path, XML otherwise. :func:`load_rexs` reads it back to the
        same gear."""
        path = os.fspath(path)
        self._native.write_rexs(path, path.lower().endswith((".rexsj", ".json")))

    def write(self, directory: "str | os.PathLike[str]") -> list:
        """Writes the files the CLI writes for the same stages (summary.json, CSV, SVG, VTK,
        report.html, and the STEP solids of ``run(..., step=True)``) into ``directory``
        (created); returns their paths."""
        path = os.fspath(directory)
        os.makedirs(path, exist_ok=True)
        return self._native.write(path)

    def __repr__(self) -> str:
        return f"Results(stages={self.stages})"


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
) -> Results:
    """Runs the pipeline on ``gear``: ``stages`` from :data:`STAGES` (default: all that
    ``wormwear run`` runs; ``wear`` needs the gear's ``[wear]`` section or ``cycles``). Life
    overrides as the CLI's flags: ``cycles`` (wheel cycles), ``step_cycles`` (fixed steps,
    wheel cycles), ``step_wear_um`` (adaptive steps, um), ``no_pitting``. ``map_position``:
    the position (0-based) whose pressure maps ``write`` draws. ``progress(event, details)``
    is called at each stage and wear state. ``step``: also build the CAD solids that ``write``
    writes as STEP (worm.step, wheel.step, and wheel_worn.step after a life), as the CLI's
    ``--step``; ``step_teeth``: the wheel's tooth count (default all), ``step_state``: the wear
    step of the map state the worn wheel shows (default the last).

    The GIL is released while it computes; Ctrl-C raises KeyboardInterrupt at the next stage or
    wear state. Raises :class:`InputError` for an input problem, :class:`ComputationError`
    for a failed computation."""
    _check_run_arguments(gear, stages, step_cycles, step_wear_um, map_position, step_teeth, step_state)
    callback = None
    if progress is not None:
        def callback(kind: str, details: str) -> None:
            progress(kind, json.loads(details))
    native = _native.run(
        gear._native,
        list(stages) if stages is not None else None,
        cycles,
        step_cycles,
        step_wear_um,
        no_pitting,
        map_position,
        callback,
        (step_teeth, step_state) if step else None,
    )
    return Results(native)


def _check_run_arguments(gear, stages, step_cycles, step_wear_um, map_position, step_teeth, step_state) -> None:
    """The arguments of :func:`run` checked at the boundary, each error naming the argument."""
    if not isinstance(gear, GearSet):
        raise TypeError(
            "run: gear must be a wormwear.GearSet (wormwear.load(path) reads a gear file), "
            f"got {type(gear).__name__} {gear!r}"
        )
    if isinstance(stages, (str, bytes)):
        raise TypeError(
            f"run: stages must be a list of stage names such as [{stages!r}], got the string "
            f"{stages!r}"
        )
    if step_cycles is not None and step_wear_um is not None:
        raise ValueError(
            "run: step_cycles (fixed steps) and step_wear_um (adaptive steps) exclude each "
            "other: give one"
        )
    for name, value in (
        ("map_position", map_position),
        ("step_teeth", step_teeth),
        ("step_state", step_state),
    ):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
            raise ValueError(f"run: {name} must be a whole number from 0 up, got {value!r}")


def _settings_json(stages, cycles, step_cycles, step_wear_um, no_pitting) -> str:
    return json.dumps(
        {
            "stages": list(stages) if stages is not None else None,
            "cycles": cycles,
            "step_cycles": step_cycles,
            "step_wear_um": step_wear_um,
            "no_pitting": no_pitting,
        }
    )


def _variants(grid, cases) -> tuple:
    if (grid is None) == (cases is None):
        raise ValueError("sweep: give grid (dotted name -> list of values) or cases (a list of dicts), one of the two")
    if grid is not None:
        parameters, variants = _native.expand_grid(json.dumps(list(dict(grid).items())))
        return parameters, json.loads(variants)
    parameters, variants = [], []
    width = len(str(len(cases)))
    for k, case in enumerate(cases):
        values = dict(case)
        name = str(values.pop("name", f"c{k + 1:0{width}d}"))
        for p in values:
            if p not in parameters:
                parameters.append(p)
        variants.append([name, values])
    return parameters, variants


def _run_variant_task(variant: list, base: GearSet, settings: str, directory: Optional[str]) -> dict:
    """One Dask task: one variant's row."""
    return json.loads(_native.run_variant(base._native, json.dumps(variant), settings, directory))


def _frame(parameters: list, rows: Iterable[dict]) -> pd.DataFrame:
    records = []
    for r in rows:
        rec = {"variant": r["variant"]}
        for p in parameters:
            rec[p] = r["parameters"].get(p)
        rec.update({k: v for k, v in r.items() if k not in ("variant", "parameters")})
        records.append(rec)
    frame = pd.DataFrame.from_records(records)
    return frame


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
    output: "str | os.PathLike[str] | None" = None,
    client: Any = None,
) -> pd.DataFrame:
    """Runs variants of ``base`` and returns one row per variant: the variant's name, its
    values, ``ok``, ``error`` and the key results (``max_pressure_pa``,
    ``contact_area_fraction``, ``te_p2p_rad``, ``power_balance``, ``efficiency``,
    ``life_cycles``, ``backlash_increase_end_m``, ``max_wear_end_m``, ``backlash_limit_m``,
    ``cycles_to_backlash_limit``, ``seconds``), as ``wormwear sweep``'s sweep.csv.

    Variants: ``grid`` (dotted name -> list of values: every combination, the first name
    slowest, named v1, v2, ...) or ``cases`` (a list of dicts of dotted names, each with an
    optional ``name``). A failing variant gives a row with its error; the others go on.

    Without ``client`` the variants run in parallel on the local cores (with ``output``, into
    that directory as ``wormwear sweep`` does: sweep.csv, sweep.html, variants/NAME/, and a
    rerun reuses finished variants). With a ``dask.distributed.Client`` the base gear is
    scattered to the workers and each variant is one task; the rows are gathered (with
    ``output``, each worker writes its variant's folder there: a directory all workers see)."""
    parameters, variants = _variants(grid, cases)
    settings = _settings_json(stages, cycles, step_cycles, step_wear_um, no_pitting)
    directory = os.fspath(output) if output is not None else None
    if client is None:
        if directory is not None:
            os.makedirs(directory, exist_ok=True)
        rows = json.loads(
            _native.sweep(base._native, parameters, json.dumps(variants), settings, directory)
        )
        return _frame(parameters, rows)
    base_future = client.scatter(base, broadcast=True)
    futures = client.map(
        _run_variant_task,
        variants,
        base=base_future,
        settings=settings,
        directory=directory,
        pure=False,
    )
    rows = client.gather(futures)
    if directory is not None:
        _native.write_sweep_csv(os.path.join(directory, "sweep.csv"), parameters, json.dumps(rows))
    return _frame(parameters, rows)


class Spread:
    """What ``wormwear.spread`` gives (MODEL §17): ``samples`` (one row per run: the sample, its
    inputs, ``ok`` and the key results, as spread.csv), ``summary`` (spread.json as a dict),
    ``percentiles`` (one row per key result: count, min, p10, p50, p90, max, mean),
    ``rank_correlation`` (results x inputs, Spearman's rho), ``sobol_indices`` (with the Sobol
    sampler: a frame of result, input, first, total; else None), ``directory`` and ``reused``
    (the samples found finished there: by an earlier run, or by Dask tasks)."""

    def __init__(self, directory: str, summary: dict, reused: int = 0):
        self.directory = directory
        self.reused = reused
        self.summary = summary
        self.samples = pd.read_csv(os.path.join(directory, "spread.csv"))
        self.percentiles = pd.DataFrame.from_dict(summary["results"], orient="index")
        self.rank_correlation = pd.DataFrame.from_dict(summary["rank_correlation"], orient="index")
        indices = summary.get("sobol_indices")
        self.sobol_indices = None
        if indices is not None:
            records = [
                {"result": result, "input": name, **(index or {"first": None, "total": None})}
                for result, by_input in indices.items()
                for name, index in by_input.items()
            ]
            self.sobol_indices = pd.DataFrame.from_records(records)

    def __repr__(self) -> str:
        return (
            f"<wormwear.Spread {self.summary['runs']} runs of {self.summary['samples']} samples "
            f"({self.summary['sampler']}), {self.summary['failed']} failed: {self.directory}>"
        )


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
    output: "str | os.PathLike[str]",
    client: Any = None,
) -> Spread:
    """The spread of ``base`` under uncertain inputs, as ``wormwear spread`` (MODEL §17):
    ``inputs`` maps dotted names of the gear file to ``(min, max)`` (uniform) or
    ``{"mean": .., "sd": .., "min": .., "max": ..}`` (normal, truncated); ``samples`` runs
    (with ``sampler="sobol"`` the base points of Saltelli's design: samples x (inputs + 2)
    runs, and the Sobol indices), ``seed``, ``fixed`` (fields set alike in every sample), the
    stages and life overrides as ``sweep``. Runs on the local cores into ``output``
    (spread.csv, spread.json, spread.html, variants/NAME/; a rerun reuses finished samples),
    or with a ``dask.distributed.Client`` one task per sample, each writing its folder in
    ``output`` (a directory all workers see), then the spread's files from them. Bad input
    raises ``InputError`` naming the field."""
    spec = json.loads(_settings_json(stages, cycles, step_cycles, step_wear_um, no_pitting))
    spec = {k: v for k, v in spec.items() if v is not None and v is not False}
    table = {
        "samples": samples,
        "seed": seed,
        "sampler": sampler,
        "inputs": {name: list(v) if isinstance(v, (tuple, list)) else dict(v) for name, v in inputs.items()},
    }
    if fixed is not None:
        table["fixed"] = dict(fixed)
    spec["spread"] = table
    directory = os.fspath(output)
    if client is not None:
        variants = json.loads(_native.spread_variants(base._native, json.dumps(spec)))
        settings = _settings_json(
            stages if stages is not None else ["ltca"], cycles, step_cycles, step_wear_um, no_pitting
        )
        os.makedirs(directory, exist_ok=True)
        base_future = client.scatter(base, broadcast=True)
        futures = client.map(
            _run_variant_task, variants, base=base_future, settings=settings, directory=directory, pure=False
        )
        client.gather(futures)
    # Locally: every sample; after Dask: the finished samples are reused, the files written.
    text, reused = _native.spread(base._native, json.dumps(spec), directory)
    return Spread(directory, json.loads(text), reused)


class Pattern:
    """What ``wormwear.pattern`` gives (MODEL §17): ``settings`` (one row per setting: name, min,
    max, start, best), ``before`` and ``after`` (the pattern's shape at the start and at the
    best settings: centre_across_face, centre_up_flank, extent_along_face, extent_up_flank),
    ``objective`` (start and best), ``path`` (search.csv: every evaluation in order),
    ``gear`` (the best gear file as a GearSet), ``summary`` (pattern.json as a dict) and
    ``directory``."""

    def __init__(self, directory: str, summary: dict):
        self.directory = directory
        self.summary = summary
        self.settings = pd.DataFrame.from_records(summary["settings"])
        self.before = summary["start"]["shape"]
        self.after = summary["best"]["shape"]
        self.objective = {"start": summary["start"]["objective"], "best": summary["best"]["objective"]}
        self.path = pd.read_csv(os.path.join(directory, "search.csv"))
        self.gear = load(os.path.join(directory, summary["best_gear_file"]))

    def __repr__(self) -> str:
        return (
            f"<wormwear.Pattern {self.summary['pattern']} pattern, objective {self.objective['start']:.3e} -> "
            f"{self.objective['best']:.3e} in {self.summary['evaluations']} evaluations "
            f"({self.summary['stopped']}): {self.directory}>"
        )


def pattern(
    base: GearSet,
    target: Mapping[str, float],
    *,
    vary: Optional[Mapping[str, Sequence[float]]] = None,
    loaded: bool = False,
    evaluations: int = 60,
    output: "str | os.PathLike[str]",
) -> Pattern:
    """The contact-pattern assistant, as ``wormwear pattern`` (MODEL §17): searches the cutting
    settings of ``base`` for the pattern closest to ``target`` (any of centre_across_face,
    centre_up_flank, extent_along_face, extent_up_flank: shares in [0, 1], the centre across
    the face from the entering to the leaving side). ``vary`` maps dotted gear-file names (and
    ``"hob.oversize_mm"``) to ``(min, max)``; None: the cutting centre distance, the hob swivel
    and the hob oversize around the base's. ``loaded``: the loaded pattern instead of the
    no-load one. Writes gear.toml (the best settings), pattern.json, search.csv, before/ and
    after/ into ``output``. Bad input raises ``InputError`` naming it."""
    bounds = None
    if vary is not None:
        bounds = []
        for name, range_ in vary.items():
            low, high = range_
            bounds.append([name, float(low), float(high)])
    directory = os.fspath(output)
    text = _native.pattern(
        base._native, json.dumps(dict(target)), json.dumps(bounds), bool(loaded), int(evaluations), directory
    )
    return Pattern(directory, json.loads(text))


def forget_kept_sector() -> None:
    """Lets go of the FE sector the root stress (S_F) keeps for the next run of the same wheel
    (up to a few hundred MB in a long session); the next S_F builds its own."""
    _native.forget_kept_sector()

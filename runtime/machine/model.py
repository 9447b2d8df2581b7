"""The runtime model: a generated module behind a small, validated API.

Units: positions mm (linear) and deg (rotary), translational errors and probe offsets mm,
angular errors rad, results mm.  Error = actual minus nominal position of the probe tip / tool
centre point in the workpiece frame.  Importing this module does not import sympy; a layout
given as a file path is derived on the fly (that path imports sympy).
"""

from __future__ import annotations

import importlib
import inspect
import types
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, require
from . import fused
from .derivation import derive_module
from .lags import lag_of_columns
from .layout import Layout, read_layout


def _module_for(layout: Layout, name_or_path) -> types.ModuleType:
    """The generated module of a shipped layout, or a freshly derived one for a layout file."""
    shipped = (str(name_or_path).upper() == layout.name.upper()
               and not str(name_or_path).endswith(".toml"))
    if shipped:
        try:
            mod = importlib.import_module(f"volerr.generated.{layout.name.lower()}")
        except ModuleNotFoundError:
            mod = None
        if mod is not None and mod.LAYOUT_SHA256 == layout.sha256:
            return mod
    return derive_module(layout)


def _floats(value, what: str) -> np.ndarray:
    """``value`` as a float array; anything that is not numbers raises InputError."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numbers, got {value!r:.60}") from None


#: a missing error parameter's value (read only, shared)
_ZERO = np.asarray(0.0)
_ZERO.flags.writeable = False
_FLOAT = _ZERO.dtype


def _case_insensitive(given: dict, names) -> dict:
    """Keys that match one of ``names`` only up to case (``x``, ``exx``) get its spelling."""
    upper = {}
    for n in names:
        upper.setdefault(n.upper(), []).append(n)
    out = {}
    for k, v in given.items():
        if k not in names and isinstance(k, str) and len(upper.get(k.upper(), ())) == 1:
            k = upper[k.upper()][0]
        if k in out:
            raise InputError(f"{k} given twice (names are case-insensitive)")
        out[k] = v
    return out


#: points per block of :func:`_blocked`: large enough that the per-block Python cost (argument
#: slicing, one ufunc call per operation) is small against the arithmetic, small enough that the
#: block's inputs and temporaries stay in the cache, so each input is read from memory once
#: (``python benchmarks/bench_volumetric.py --blocks`` measures 2048 ... 65536)
BLOCK = 16384


def _blocked(fn, kwargs: dict, n: int, n_out: int = 3, finite: list | None = None,
             check_rows=None, trig: dict | None = None) -> np.ndarray:
    """``fn(**kwargs)`` (a generated function returning ``n_out`` broadcastable outputs)
    evaluated block by block into one (n, n_out) array.  Arguments that are (n,) arrays are
    sliced (views, also of strided columns); scalars and (1,) arrays pass whole.

    The generated function is run as its fused block kernel (:mod:`.fused`): outputs written
    straight into the rows of the result, arguments that are scalar 0 folded away; a function
    that cannot be fused is called as it is.  ``finite``: a list that receives one bool, whether
    every result is finite (checked block by block while the block is in the cache).
    ``check_rows``: (rows (n, k), check) -- ``check(rows[block])`` is called before each block
    is evaluated (the inputs' validation, done while the block is read anyway).  ``trig``:
    argument -> (its sine, its cosine) (n,), computed once for several functions
    (:meth:`Model.prepared`), which the fused kernel reads instead of computing them."""
    if n == 1 and check_rows is None:   # one point: its kernel on the values (the same bits)
        out = _point(fn, kwargs, n_out, trig or {})
        if out is not None:
            return _one_block(lambda: None, out, finite, None)
    scalars = {k for k, v in kwargs.items() if _ndim(v) == 0}
    zeros = frozenset(k for k in scalars if kwargs[k] == 0)
    trig = trig or {}
    kernel = (fused.numpy_kernel(fn, zeros, frozenset(scalars) - zeros, frozenset(trig))
              if fused.n_outputs(fn) == n_out else None)
    if kernel is not None:
        kernel, n_scratch = kernel
        kwargs = {**kwargs, **{fused.trig_name(f, a): v for a, sc in trig.items()
                               for f, v in zip(("sin", "cos"), sc)}}
        scratch = np.empty((n_scratch, min(BLOCK, n)))
    out = np.empty((n, n_out))
    if 0 < n <= BLOCK:      # one block: the arguments whole (what slicing them would give)
        if kernel is not None:
            return _one_block(lambda: kernel(out, scratch, **kwargs), out, finite, check_rows)

        def columns():
            for i, c in enumerate(fn(**kwargs)):
                out[:, i] = c
        return _one_block(columns, out, finite, check_rows)
    ok = True
    sliced = [k for k, v in kwargs.items() if _per_point(v, n)]
    # a dict argument (the ``lags`` of a generated function): its (n,) arrays sliced as well
    nested = {k: [j for j, a in v.items() if _per_point(a, n)] for k, v in kwargs.items()
              if isinstance(v, Mapping)}
    for start in range(0, n, BLOCK):
        sl = slice(start, min(start + BLOCK, n))
        kw = dict(kwargs)
        for k in sliced:
            kw[k] = kwargs[k][sl]
        for k, keys in nested.items():
            kw[k] = {**kwargs[k], **{j: kwargs[k][j][sl] for j in keys}}
        if check_rows is not None:
            check_rows[1](check_rows[0][sl])
        if kernel is not None:
            kernel(out[sl], scratch[:, :sl.stop - sl.start], **kw)
        else:
            for i, c in enumerate(fn(**kw)):
                out[sl, i] = c
        if finite is not None and ok:
            with np.errstate(over="ignore"):  # NaN/inf anywhere -> sum not finite
                ok = bool(np.isfinite(out[sl].sum()))
    if finite is not None:
        finite.append(ok or bool(np.isfinite(out).all()))  # ok False: sum overflow or NaN
    return out


def _one_block(evaluate, out: np.ndarray, finite, check_rows) -> np.ndarray:
    """:func:`_blocked` of at most ``BLOCK`` points: the same steps on the whole arguments,
    without the per-argument slicing (per-chunk overhead of short evaluations);
    ``evaluate()`` fills ``out``."""
    if check_rows is not None:
        check_rows[1](check_rows[0])
    evaluate()
    if finite is not None:
        with np.errstate(over="ignore"):  # NaN/inf anywhere -> sum not finite
            ok = bool(np.isfinite(out.sum()))
        finite.append(ok or bool(np.isfinite(out).all()))  # ok False: sum overflow or NaN
    return out


def _point(fn, kwargs: dict, n_out: int, trig: dict) -> np.ndarray | None:
    """``fn`` at one point as :func:`_blocked` evaluates it, (1, n_out), by its
    :func:`volerr.machine.fused.point_kernel` (the numpy kernel's bits) for the arguments'
    pattern of scalars and zeros; None when there is none or an argument is of another kind
    (a dict of lags, another dtype): the numpy kernel then.  One pass over the arguments: the
    scalars, the zeros among them and every value as a float."""
    if fused.n_outputs(fn) != n_out:
        return None
    values, scalars, zeros = {}, [], []
    for k, v in kwargs.items():
        t = type(v)
        if t is np.ndarray:
            if v.dtype is not _FLOAT or v.size != 1:
                return None
            if v.ndim == 0:
                scalars.append(k)
                if v == 0:
                    zeros.append(k)
            v = v.item()
        elif t is float or t is int or t is np.float64:
            scalars.append(k)
            if v == 0:
                zeros.append(k)
        else:
            return None
        values[k] = v
    for a, sc in trig.items():
        for f, v in zip(("sin", "cos"), sc):
            if type(v) is not np.ndarray or v.dtype is not _FLOAT or v.size != 1:
                return None
            values[fused.trig_name(f, a)] = v.item()
    zeros = frozenset(zeros)
    kernel = fused.point_kernel(fn, zeros, frozenset(scalars) - zeros, frozenset(trig))
    if kernel is None:
        return None
    out = np.empty((1, n_out))
    kernel(out, **values)
    return out


def _ndim(v) -> int:
    """``np.ndim(v)``, without its array conversion for a float or an array."""
    if type(v) is float:
        return 0
    return v.ndim if isinstance(v, np.ndarray) else np.ndim(v)


def _per_point(v, n: int) -> bool:
    """Whether argument ``v`` holds one value per point ((n,), n > 1): sliced per block."""
    return np.ndim(v) == 1 and np.shape(v)[0] == n and n > 1


def _columns(components, n: int) -> np.ndarray:
    """Generated outputs (tuple of broadcastable arrays) -> (n, len) float array."""
    return np.stack([np.broadcast_to(c, (n,)) for c in components], axis=-1).astype(
        float, copy=False)


@dataclass(frozen=True)
class Prepared:
    """Axis positions validated once (:meth:`Model.prepared`): ``values`` axis -> (n,) array
    (rotary axes in rad, the model's own copies), ``n`` the number of points, ``trig`` rotary
    axis -> (its sine, its cosine) (n,).  The evaluation methods take it in place of
    positions; their fused kernels read these sines and cosines instead of computing them
    again (the same values)."""

    values: dict
    n: int
    trig: dict


def _trig(positions) -> dict | None:
    """The sines and cosines of prepared positions (None for others)."""
    return positions.trig if isinstance(positions, Prepared) else None


def _offset(probe, tool):
    """The probe/tool offset given as ``probe=`` (the API name) or its alias ``tool=``."""
    require(probe is None or tool is None, "give the offset as probe= or tool=, not both")
    value = probe if probe is not None else tool
    return (0.0, 0.0, 0.0) if value is None else value


@dataclass
class Model:
    """A machine's error model. Create with :func:`load`."""

    layout: Layout
    module: types.ModuleType

    # ---- description -------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.layout.name

    @property
    def axes(self) -> tuple[str, ...]:
        """Axis names in position-array column order."""
        return tuple(self.module.AXES)

    @property
    def rotary_axes(self) -> tuple[str, ...]:
        return tuple(self.module.ROTARY_AXES)

    @property
    def parameters(self) -> tuple[str, ...]:
        """ISO 230-1 names of the error parameters, in model order."""
        return tuple(self.module.PARAMETERS)

    @property
    def parameter_axis(self) -> dict:
        """Parameter -> axis whose position it depends on (None for constants)."""
        return dict(self.module.PARAMETER_AXIS)

    @property
    def parameter_kind(self) -> dict:
        """Parameter -> ``translational`` (mm), ``angular`` (rad), ``squareness`` (rad),
        ``location`` (mm or rad by its letter) or ``effect`` (:mod:`volerr.machine.iso_names`)."""
        kinds = getattr(self.module, "PARAMETER_KIND", None)
        return dict(kinds) if kinds is not None else dict(self.layout.parameter_kind)

    @property
    def paper_symbols(self) -> dict:
        """ISO name -> symbol (with sign) used for it in the source document of the layout."""
        return dict(self.layout.paper_symbols)

    @property
    def covariates(self) -> tuple[str, ...]:
        """Covariates of declared effects (``T_C``, ``t_s`` ...): extra inputs, () usually."""
        return tuple(getattr(self.module, "COVARIATES", ()))

    @property
    def lags(self) -> tuple:
        """Lags of declared effects: ((canonical text ``lag(C, tau_s)``, column C, tau_s,
        time column), ...) (:mod:`volerr.machine.lags`); () usually."""
        return tuple(getattr(self.module, "LAGS", ()))

    @property
    def symbols(self) -> tuple[str, ...]:
        """Nominal symbols of the chain (``probe.Zp``, ``axis.C``, ``param.d``, ``frame.F.x``
        ...; :attr:`volerr.machine.layout.Layout.symbols`) in the order of the generated
        ``symbol_sensitivity``; () for a module generated before it existed."""
        if not hasattr(self.module, "symbol_sensitivity"):
            return ()
        return tuple(getattr(self.module, "SYMBOLS", ()))

    @property
    def travel(self) -> dict:
        """Axis -> (min, max) travel, mm or deg."""
        return {a: self.layout.axes[a].travel for a in self.axes}

    # ---- input handling ----------------------------------------------------------
    def positions(self, positions) -> dict:
        """Validate positions (dict or (N, n_axes) array, mm/deg) -> dict of float arrays,
        rotary axes converted to rad."""
        return self._validated(positions)[0]

    def _validated(self, positions, defer: bool = False) -> tuple[dict, int, np.ndarray | None]:
        """:meth:`positions`, their number of points, and with ``defer`` an (N, n_axes) array
        whose finiteness check is left to the caller (:func:`_blocked` checks it block by block
        while the block is in the cache: one pass less over memory); None when checked here."""
        deferred = None
        if isinstance(positions, Prepared):
            return dict(positions.values), positions.n, None
        if isinstance(positions, Mapping):
            positions = _case_insensitive(dict(positions), self.axes)
            unknown = set(positions) - set(self.axes)
            if unknown:
                raise InputError(f"{self.name}: unknown axis {sorted(unknown, key=str)[0]!r}; "
                                 f"axes are {' '.join(self.axes)}")
            missing = [a for a in self.axes if a not in positions]
            if missing:
                raise InputError(f"{self.name}: positions lack axis {missing[0]}")
            cols = {a: _floats(positions[a], f"position {a}") for a in self.axes}
        else:
            arr = _floats(positions, "positions")
            if arr.ndim == 1:
                arr = arr[None, :]
            axes = self.axes
            if not (arr.ndim == 2 and arr.shape[1] == len(axes)):
                raise InputError(f"{self.name}: positions must have {len(axes)} columns "
                                 f"({' '.join(axes)}), got shape {arr.shape}")
            if defer and arr.flags.c_contiguous and len(arr) > 1:
                deferred = arr
            else:
                self._check_rows(arr)
            # columns: strided views, no copy (all of one length: nothing to broadcast)
            rot = self.rotary_axes
            return ({a: np.deg2rad(arr[:, i]) if a in rot else arr[:, i]
                     for i, a in enumerate(axes)}, len(arr), deferred)
        for a, v in cols.items():
            if isinstance(positions, Mapping) and not np.isfinite(v).all():
                raise InputError(f"{self.name}: position {a} has NaN or infinite values")
        try:
            shape = np.broadcast_shapes(*(np.shape(v) for v in cols.values()))
        except ValueError:
            raise InputError(f"{self.name}: positions of the axes differ in length: " + ", ".join(
                f"{a} {np.size(v)}" for a, v in cols.items())) from None
        out = {}
        for a, v in cols.items():
            if v.shape != shape or v.ndim != 1:
                v = np.broadcast_to(v, shape).ravel() if shape else np.atleast_1d(v)
            out[a] = np.deg2rad(v) if a in self.rotary_axes else v
        return out, len(next(iter(out.values()))), deferred

    def _check_rows(self, arr: np.ndarray) -> None:
        """(m, n_axes) positions finite, else InputError naming the axis.  One contiguous pass
        (a sum: NaN/inf anywhere makes it non-finite; only then, or on an overflow of the sum,
        the exact check)."""
        with np.errstate(over="ignore", invalid="ignore"):
            finite = bool(np.isfinite(arr.sum())) or bool(np.isfinite(arr).all())
        if not finite:
            bad = next(a for i, a in enumerate(self.axes) if not np.isfinite(arr[:, i]).all())
            raise InputError(f"{self.name}: position {bad} has NaN or infinite values")

    def _points(self, positions) -> tuple[dict, int]:
        """Validated positions (see :meth:`positions`) and their number of points."""
        pos, n, _ = self._validated(positions)
        return pos, n

    def prepared(self, positions) -> Prepared:
        """Positions (as :meth:`positions` takes them, mm / deg) validated once, with the sine
        and cosine of every rotary axis: for several evaluations at the same positions
        (:meth:`nominal_position`, :meth:`exact_error`, :meth:`orientation_error`,
        :meth:`tool_axis` ... take it in place of positions and give the same values)."""
        pos, n = self._points(positions)
        values = {a: np.array(v, dtype=float) for a, v in pos.items()}  # not the caller's
        return Prepared(values, n, {a: (np.sin(values[a]), np.cos(values[a]))
                                    for a in self.rotary_axes})

    def _probe(self, probe, n: int) -> dict:
        p = _floats(probe, "probe offset")
        if p.shape not in ((3,), (n, 3)):
            raise InputError(f"probe offset must be (3,) or ({n}, 3), got {p.shape}")
        require(np.isfinite(p).all(), "probe offset has NaN values")
        if p.shape == (3,):  # one offset for all points: scalars broadcast in the generated code
            return {"Xp": float(p[0]), "Yp": float(p[1]), "Zp": float(p[2])}
        return {"Xp": p[:, 0], "Yp": p[:, 1], "Zp": p[:, 2]}

    def _covariates(self, covariates, n: int) -> dict:
        """Covariate values for a model with declared effects ({} for the others)."""
        covariates = dict(covariates or {})
        out = {}
        for c in self.covariates:
            require(c in covariates, f"{self.name}: covariate {c} is needed (declared effects)")
            v = _floats(covariates[c], f"covariate {c}")
            require(v.shape in ((), (n,), (1,)), f"covariate {c} must be a scalar or ({n},) array")
            require(np.all(np.isfinite(v)), f"covariate {c} has NaN or infinite values")
            out[c] = v
        if self.lags:   # a lag of a longer series, at these points (else computed from these)
            given = {k: covariates[k] for k, *_ in self.lags if k in covariates}
            if n > BLOCK:   # evaluated in blocks: each lag filtered over the whole series here
                for key, column, tau, time in self.lags:
                    if key not in given and time in out and np.shape(out.get(column)) == (n,):
                        given[key] = lag_of_columns(out, column, tau, time)
            out["lags"] = given or None
        return out

    def _errors(self, errors, n: int) -> dict:
        require(errors is None or isinstance(errors, Mapping),
                f"errors must be a dict {{name: value}}, got {type(errors).__name__}")
        names = self.parameters
        errors = dict(errors or {})
        if not errors.keys() <= set(names):     # (names spelt as the model does: kept as given)
            errors = _case_insensitive(errors, names)
        unknown = set(errors) - set(names)
        if unknown:
            raise InputError(f"{self.name}: unknown error parameter {sorted(unknown, key=str)[0]!r}")
        out = {}
        shapes = ((), (n,), (1,))
        for p in names:
            v = errors.get(p, _ZERO)
            if type(v) is not np.ndarray or v.dtype is not _FLOAT:    # (else _floats(v) is v)
                v = _floats(v, f"error {p}")
            if v.shape not in shapes:
                raise InputError(f"error {p} must be a scalar or ({n},) array")
            out[p] = v
        return out

    @staticmethod
    def _evaluate(fn, kwargs: dict, n: int, errs: dict, check_rows=None,
                  trig=None) -> np.ndarray:
        """``fn`` block by block (:func:`_blocked`), the result checked for NaN there.  NaN in
        any input propagates to the result, so the inputs are looked at only then, to name the
        error parameter that caused it."""
        finite: list = []
        out = _blocked(fn, kwargs, n, finite=finite, check_rows=check_rows, trig=trig)
        if not finite[0]:
            for name, v in errs.items():
                if not np.all(np.isfinite(v)):
                    raise InputError(f"error {name} has NaN or infinite values")
            raise InputError("the model evaluated to NaN or infinity (values too large?)")
        return out

    # ---- evaluation --------------------------------------------------------------
    def volumetric_error(self, positions, errors=None, probe=(0.0, 0.0, 0.0),
                         direction=None, probe_error=None, covariates=None) -> np.ndarray:
        """First-order volumetric error: actual minus nominal tool point relative to the
        workpiece.

        Parameters
        ----------
        positions : dict or array_like
            ``{axis: scalar or (N,)}`` or shape (N, n_axes) in :attr:`axes` order; mm (linear),
            deg (rotary).
        errors : dict, optional
            ``{name: scalar or (N,)}``, mm (translational) / rad (angular); missing names are 0.
        probe : array_like, shape (3,) or (N, 3)
            Probe / tool offset, mm.
        direction : array_like, shape (3,) or (N, 3), optional
            Probing direction ``n`` (outward surface normal), with ``probe_error``.
        probe_error : callable or array_like, optional
            Probe(n), mm: a callable of (N, 3) directions (:class:`volerr.probe.ProbeMap`) or
            (N,) values.  Pahk eq. (17): ``+ Probe(n) n`` is added (eq. 17's ``- Probe M`` with
            ``M = -n`` the contact direction), so the result stays "actual minus nominal": a
            CMM reports the point minus this error.
        covariates : dict, optional
            Values of the layout's covariates (e.g. temperatures), scalar or (N,).

        Returns
        -------
        ndarray, shape (N, 3)
            dx, dy, dz, mm.
        """
        pos, n, rows = self._validated(positions, defer=True)
        errs = self._errors(errors, n)
        out = self._evaluate(
            self.module.volumetric_error,
            {**pos, **self._covariates(covariates, n), **self._probe(probe, n), **errs}, n, errs,
            check_rows=None if rows is None else (rows, self._check_rows),
            trig=_trig(positions))
        if direction is not None or probe_error is not None:
            out = out + self._probe_term(direction, probe_error, n)
        return out

    def _probe_term(self, direction, probe_error, n: int) -> np.ndarray:
        require(direction is not None and probe_error is not None,
                "combined model needs both a probing direction and a probe error")
        m = _floats(direction, "probing direction")
        require(m.shape in ((3,), (n, 3)), f"probing direction must be (3,) or ({n}, 3), "
                                           f"got {m.shape}")
        require(np.all(np.isfinite(m)), "probing direction has NaN or infinite values")
        m = np.broadcast_to(m, (n, 3))
        norm = np.linalg.norm(m, axis=1, keepdims=True)
        require(np.all(norm > 0), "probing direction must not be the zero vector")
        m = m / norm
        value = probe_error(m) if callable(probe_error) else probe_error
        value = _floats(value, "probe error")
        require(value.shape in ((), (1,), (n,)), f"probe error must be a scalar or ({n},) "
                                                 f"array, got {value.shape}")
        require(np.all(np.isfinite(value)), "probe error has NaN or infinite values")
        value = np.broadcast_to(value, (n,))
        return value[:, None] * m

    def exact_error(self, positions, errors=None, probe=(0.0, 0.0, 0.0),
                    covariates=None) -> np.ndarray:
        """Error from the exact (not small-angle) chain, (N, 3) mm: for checks and simulation."""
        pos, n = self._points(positions)
        errs = self._errors(errors, n)
        return self._evaluate(
            self.module.exact_error,
            {**pos, **self._covariates(covariates, n), **self._probe(probe, n), **errs}, n, errs,
            trig=_trig(positions))

    def sensitivity(self, positions, probe=(0.0, 0.0, 0.0), covariates=None) -> np.ndarray:
        """Sensitivity of the volumetric error to every parameter.

        Parameters
        ----------
        positions : dict or array_like
            As :meth:`volumetric_error` (mm / deg).
        probe : array_like, shape (3,) or (N, 3)
            Probe / tool offset, mm.
        covariates : dict, optional
            As :meth:`volumetric_error`.

        Returns
        -------
        ndarray, shape (N, 3, n_parameters)
            d(dx, dy, dz)/d(parameter) in :attr:`parameters` order: mm/mm or mm/rad.
        """
        pos, n = self._points(positions)
        return self._sensitivity(pos, n, probe, covariates)

    def _sensitivity(self, pos: dict, n: int, probe, covariates) -> np.ndarray:
        s = self.module.sensitivity(**pos, **self._covariates(covariates, n),
                                    **self._probe(probe, n))
        return np.moveaxis(np.broadcast_to(s, s.shape[:2] + (n,)), -1, 0)

    def random_error(self, positions, sigmas, probe=(0.0, 0.0, 0.0),
                     method: str = "exact", covariates=None) -> np.ndarray:
        """Standard uncertainty of the volumetric error (independent parameters).

        Parameters
        ----------
        positions : dict or array_like
            As :meth:`volumetric_error` (mm / deg).
        sigmas : dict
            ``{name: standard deviation, scalar or (N,)}``, mm / rad, non-negative; missing
            names are 0.
        probe : array_like, shape (3,) or (N, 3)
            Probe / tool offset, mm.
        method : {"exact", "termwise"}
            ``"exact"``: first-order propagation sqrt(sum((dD/dp)^2 sigma_p^2));
            ``"termwise"``: Pahk's printed quadrature (eq. 5, 8), which squares each term alone
            and drops cross terms such as ``2 Z Zp``.
        covariates : dict, optional
            As :meth:`volumetric_error`.

        Returns
        -------
        ndarray, shape (N, 3)
            Standard uncertainties of dx, dy, dz, mm.
        """
        require(method in ("exact", "termwise"), f"unknown random-error method {method!r}")
        pos, n = self._points(positions)
        sig = self._errors(sigmas, n)
        for k, v in sig.items():
            require(np.all(np.isfinite(v)), f"error {k} has NaN or infinite values")
            require(np.all(v >= 0), f"standard deviation {k} must not be negative")
        if method == "termwise":
            return _blocked(self.module.random_error_termwise,
                            {**pos, **self._covariates(covariates, n), **self._probe(probe, n),
                             **{f"s_{k}": v for k, v in sig.items()}}, n)
        return _blocked(self.module.random_error_exact,
                        {**pos, **self._covariates(covariates, n), **self._probe(probe, n),
                         **{f"s_{k}": v for k, v in sig.items()}}, n)

    def transfer(self, measured: dict, offsets, angular: dict | None = None) -> dict:
        """Re-reference errors measured at an offset (Pahk sec. 2.3).

        ``measured``: {name: value (mm or rad), scalar or array} as measured with the
        functional point at ``offsets`` = (Xo, Yo, Zo) mm from the axis' reference point (for
        squareness: measured at that position).  ``angular``: the angular errors (rad) there,
        defaulting to the values in ``measured``.  Returns the reference values; parameters
        without a transfer rule pass through unchanged."""
        require(hasattr(self.module, "transfer_shift"), f"{self.name} has no transfer rules")
        measured = _case_insensitive(dict(measured), self.parameters)
        angular = _case_insensitive(dict(angular), self.parameters) if angular else angular
        unknown = set(measured) - set(self.parameters)
        if unknown:
            raise InputError(f"{self.name}: unknown error parameter {sorted(unknown, key=str)[0]!r}")
        try:
            o = np.asarray(offsets, dtype=float)
        except (TypeError, ValueError):
            raise InputError("offsets must be (Xo, Yo, Zo) numbers, mm") from None
        require(o.shape[-1:] == (3,), "offsets must be (Xo, Yo, Zo)")
        require(np.all(np.isfinite(o)), "offsets have NaN or infinite values")
        values = {**{p: 0.0 for p in self.parameters}, **measured, **(angular or {})}
        args = inspect.signature(self.module.transfer_shift).parameters
        kw = {a: values[a] for a in args if a not in ("Xo", "Yo", "Zo")}
        shift = self.module.transfer_shift(Xo=o[..., 0], Yo=o[..., 1], Zo=o[..., 2], **kw)
        return {k: np.asarray(v) - (np.asarray(shift[k]) if k in shift else 0.0)
                for k, v in measured.items()}

    def nominal_position(self, positions, probe=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Nominal probe/tool tip in the workpiece frame, (N, 3) mm."""
        pos, n = self._points(positions)
        return _blocked(self.module.nominal_position, {**pos, **self._probe(probe, n)}, n,
                        trig=_trig(positions))

    def forward(self, positions, probe=None, *, tool=None) -> np.ndarray:
        """Nominal tool tip and tool axis in the workpiece frame.

        Parameters
        ----------
        positions : dict or array, shape (N, n_axes)
            Axis positions, mm (linear) and deg (rotary).
        probe : array, shape (3,) or (N, 3), optional
            Probe/tool offset in the tool frame, mm (default 0).  ``tool=`` is an alias.

        Returns
        -------
        array, shape (N, 6)
            Tool tip x, y, z (mm) and unit tool axis i, j, k."""
        pos, n = self._points(positions)
        tip = self.module.nominal_position(**pos, **self._probe(_offset(probe, tool), n))
        return np.concatenate([_columns(tip, n), _columns(self.module.tool_axis(**pos), n)],
                              axis=1)

    def tool_axis(self, positions) -> np.ndarray:
        """Nominal unit tool axis i, j, k in the workpiece frame, (N, 3): the last three
        columns of :meth:`forward` (the same values), without computing the tool tip."""
        pos, n = self._points(positions)
        return _blocked(self.module.tool_axis, pos, n, trig=_trig(positions))

    def inverse(self, target, probe=None, near=None, *, tool=None) -> np.ndarray:
        """Five-axis only: axis positions (N, n_axes), mm / deg, that give the tool tip and tool
        axis ``target`` (N, 6) = x, y, z, i, j, k; ``near`` picks the branch, the turn and an
        undetermined rotary axis (see :func:`volerr.machine.kinematics.inverse`).  ``probe``:
        tool offset (3,) mm, ``tool=`` an alias."""
        from .kinematics import inverse

        return inverse(self, target, _offset(probe, tool), near)

    def linear_positions(self, targets, rotary: dict | None = None, probe=(0.0, 0.0, 0.0)
                         ) -> dict:
        """Positions of the linear axes that put the nominal tool point (offset ``probe``) at
        ``targets`` (N, 3) in the workpiece frame, the rotary axes held at ``rotary`` {axis:
        scalar or (N,) deg}: ``{axis: (N,)}`` for every axis, mm / deg.  Exact: at fixed rotary
        positions the nominal chain is affine in the linear axes."""
        targets = np.atleast_2d(_floats(targets, "targets"))
        n = len(targets)
        rotary = dict(rotary or {})
        lin = [a for a in self.axes if a not in self.rotary_axes]
        require(len(lin) == 3, f"{self.name}: placing the tool point needs three linear axes")
        missing = [a for a in self.rotary_axes if a not in rotary]
        require(not missing, f"give the position of rotary axis "
                             f"{missing[0] if missing else ''}")
        base = {**{a: np.zeros(n) for a in lin},
                **{a: np.broadcast_to(_floats(rotary[a], f"position {a}"), (n,))
                   for a in self.rotary_axes}}
        t0 = self.nominal_position(base, probe)
        J = np.empty((n, 3, 3))
        for k, a in enumerate(lin):
            step = dict(base)
            step[a] = np.ones(n)
            J[:, :, k] = self.nominal_position(step, probe) - t0
        q = np.linalg.solve(J, (targets - t0)[:, :, None])[:, :, 0]
        return {a: (q[:, lin.index(a)] if a in lin else np.asarray(base[a], float))
                for a in self.axes}

    def orientation_error(self, positions, errors=None, covariates=None) -> np.ndarray:
        """First-order error of the tool-axis direction, (N, 3), rad."""
        pos, n = self._points(positions)
        errs = self._errors(errors, n)
        return self._evaluate(self.module.orientation_error,
                              {**pos, **self._covariates(covariates, n), **errs}, n, errs,
                              trig=_trig(positions))


def load(name_or_path) -> Model:
    """Load a machine's error model.

    Parameters
    ----------
    name_or_path : str or path
        A shipped layout name (``"MB1"``, ``"DMU50"`` ...; its generated module is imported,
        no sympy) or a layout ``.toml`` file (derived on the fly; imports sympy).

    Returns
    -------
    Model
        Positions in mm (linear) and deg (rotary); errors in mm / rad; results mm, shape
        (N, 3) for N points.

    Raises
    ------
    volerr.errors.InputError
        Unknown layout or a defective layout file (one line)."""
    layout = read_layout(name_or_path)
    if not isinstance(layout, Layout):  # pragma: no cover - defensive
        raise InputError(f"not a layout: {name_or_path}")
    return Model(layout, _module_for(layout, name_or_path))

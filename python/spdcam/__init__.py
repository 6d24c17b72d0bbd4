"""spdcam: the spectral power distribution (SPD) of the light from a photo of a colour chart.

A thin layer over spdcam's Rust libraries (the same code as the ``spdcam`` command line):
photos and feature rows in, numpy arrays out, errors as :class:`SpdcamError` with the
command line's messages, and ``to_colour()`` for colour-science users.

>>> import spdcam
>>> e = spdcam.estimate("examples/sg-telelumen.jpg")        # doctest: +SKIP
>>> e.wavelengths, e.spd, e.xy, e.cct, e.detection.chart      # doctest: +SKIP
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import SpdcamError

__version__: str = _native.__version__

__all__ = [
    "SpdcamError",
    "Model",
    "Detection",
    "Estimate",
    "Estimates",
    "load_model",
    "shipped_model",
    "charts",
    "read_photo",
    "estimate",
    "estimate_places",
    "estimate_features",
    "LIGHT_KINDS",
    "METRICS",
    "Rendering",
    "render",
    "Dataset",
    "generate",
    "train",
    "finetune",
    "CAN_TRAIN",
    "__version__",
]

PhotoLike = Union[str, "os.PathLike[str]", bytes, np.ndarray]
PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[int, int], None]

DEFAULT_RANGE = "400-700:5"
#: The kinds of light ``estimate(light=…)`` takes (``spdcam light-kinds list``), from the
#: library's one classification of light.
LIGHT_KINDS: tuple[str, ...] = tuple(_native.light_kinds())
#: The single-number metrics, from the library's metric registry: one dict per metric with
#: its ``key`` (as in :attr:`Estimate.metrics` and :attr:`Estimate.metric_uncertainty`),
#: ``symbol``, ``label``, ``unit``, ``group``, ``explanation`` and whether it has a
#: ``calibrated`` interval.
METRICS: tuple[dict[str, Any], ...] = tuple(_native.metric_registry())


class Model:
    """A set of trained models; an estimate picks the one for the chart a photo shows.

    Get the shipped models with :func:`shipped_model` and one model file (``.spdm``) with
    :func:`load_model`.
    """

    def __init__(self, native: "_native.Models") -> None:
        self._native = native
        described = native.describe()
        #: The models' names as messages give them.
        self.names: list[str] = [d[0] for d in described]
        #: The chart each model reads (``None`` when the file names none).
        self.charts: list[Optional[str]] = [d[1] for d in described]
        #: The feature columns each model reads (``p01_r, p01_g, …``).
        self.feature_names: list[list[str]] = [d[2] for d in described]
        #: The wavelength grid each model estimates, ``START-END:STEP`` in nm.
        self.grids: list[str] = [d[3] for d in described]

    def __repr__(self) -> str:
        return f"Model({', '.join(self.names)})"


_SHIPPED: Optional[Model] = None


def shipped_model() -> Model:
    """The models shipped inside spdcam, one per chart (loaded once)."""
    global _SHIPPED
    if _SHIPPED is None:
        _SHIPPED = Model(_native.Models.shipped())
    return _SHIPPED


def load_model(path: Union[str, "os.PathLike[str]"]) -> Model:
    """One model from a ``.spdm`` file (as made by ``spdcam train``)."""
    return Model(_native.Models.load(os.fspath(path)))


def charts() -> dict[str, str]:
    """The charts spdcam knows by name, from its chart registry: the name ``chart``
    arguments take and results give (``colorchecker24``, ``colorchecker_sg140``, …) → the
    name people know the chart by (``ColorChecker 24``, ``ColorChecker Digital SG``)."""
    return {name: shown for name, shown, _ in _native.charts()}


def _models(model: Union[Model, str, "os.PathLike[str]", None]) -> "_native.Models":
    if model is None:
        return shipped_model()._native
    if isinstance(model, Model):
        return model._native
    return load_model(model)._native


@dataclass(frozen=True)
class Detection:
    """Where the chart is in a photo and what its patches gave."""

    #: The chart found, by the name ``chart`` arguments take (e.g. ``colorchecker_sg140``);
    #: :attr:`chart_name` is the name people know it by.
    chart: str
    #: ``"detected"`` or ``"corners"`` (given by the caller).
    method: str
    #: 0…1: how sure the chart's placement and orientation are (below 0.8: check it).
    confidence: float
    #: The chart's outer corners in photo pixels, TL, TR, BR, BL: shape (4, 2).
    corners: np.ndarray
    #: Chart coordinates (patch pitch units) → photo pixels: shape (3, 3).
    homography: np.ndarray
    #: The feature columns, ``p01_r, p01_g, …``.
    feature_names: list[str]
    #: The model's input: mean encoded sRGB (0–255) of each feature patch, flattened.
    features: np.ndarray
    #: Every patch's robust mean encoded sRGB (0–255): shape (patches, 3).
    patch_rgb: np.ndarray
    #: Every patch's standard deviation (0–255): shape (patches, 3).
    patch_std: np.ndarray
    #: Every patch's centre in photo pixels: shape (patches, 2).
    patch_centres: np.ndarray
    #: Patches with more than a quarter of their pixels clipped (their value is a lower bound).
    clipped: np.ndarray
    #: Patches nearly black in every channel (their colour is mostly noise).
    dark: np.ndarray
    #: What the user should know (clipping, low confidence, dark patches).
    warnings: list[str]
    #: The photo's size in pixels, (width, height).
    size: tuple[int, int]
    #: For a camera raw file (DNG, CR2, CR3, NEF, ARW, RAF, …): what its mosaic said
    #: (``camera``; ``light_xy``, the light's CIE 1931 xy from the chart's grey patches
    #: through the file's own colour matrices, before their bias for the estimated shape is
    #: taken off; ``neutral_patches``; ``colour``, how the matrices were used, with
    #: ``forward_matrix``; ``gain_maps_applied``, the DNG's lens-shading gain maps applied;
    #: ``opcodes_skipped``, its other opcodes, not applied); ``None`` for a JPEG, PNG or TIFF.
    raw: Optional[dict[str, Any]] = None
    #: For one of several charts in a photo (:func:`estimate_places`): its place,
    #: ``{"number": 1-based from left to right, "of": how many, "centre": [x, y] px}``;
    #: ``None`` for a photo of one chart.
    place: Optional[dict[str, Any]] = None

    @property
    def chart_name(self) -> str:
        """The chart found as people know it, one name per physical chart (e.g.
        ``ColorChecker Digital SG``), as the command line and the report name it."""
        return _native.shown_chart_name(self.chart)

    @staticmethod
    def _from_json(p: dict[str, Any]) -> "Detection":
        patches = p["patches"]
        return Detection(
            chart=p["chart"],
            method=p["method"],
            confidence=float(p["confidence"]),
            corners=np.asarray(p["corners"], dtype=float),
            homography=np.asarray(p["homography"], dtype=float),
            feature_names=list(p["feature_names"]),
            features=np.asarray(p["features"], dtype=np.float32),
            patch_rgb=np.asarray([q["rgb"] for q in patches], dtype=np.float32),
            patch_std=np.asarray([q["std"] for q in patches], dtype=np.float32),
            patch_centres=np.asarray([q["centre"] for q in patches], dtype=float),
            clipped=np.asarray([q["clipped"] for q in patches], dtype=bool),
            dark=np.asarray([q["dark"] for q in patches], dtype=bool),
            warnings=list(p["warnings"]),
            size=(int(p["width"]), int(p["height"])),
            raw=p.get("raw"),
            place=p.get("place"),
        )


def _to_colour(wavelengths: np.ndarray, spd: np.ndarray, name: str) -> Any:
    try:
        import colour
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_colour() needs colour-science: pip install colour-science") from e
    return colour.SpectralDistribution(dict(zip(wavelengths.tolist(), spd.tolist())), name=name)


@dataclass(frozen=True)
class Estimate:
    """One estimate of the light: its SPD and what it means."""

    #: The photo's name (file name, or the ``source`` given), or ``estimate_N`` for rows.
    name: str
    #: The model that made it.
    model: str
    #: The SPD's wavelengths (nm).
    wavelengths: np.ndarray
    #: The relative SPD, peak 1.
    spd: np.ndarray
    #: CIE 1931 2° chromaticity of the SPD.
    xy: np.ndarray
    #: Correlated colour temperature (K, Ohno 2014); ``None`` farther than |Duv| 0.05.
    cct: Optional[float]
    #: Distance from the Planckian locus in CIE 1960 uv; ``None`` with ``cct``.
    duv: Optional[float]
    #: Where the chart was and what it gave (estimates from photos).
    detection: Optional[Detection] = None
    #: The lighting-quality metrics of the SPD as the library computes them (CRI, TM-30,
    #: α-opic, …; ``spdcam estimate --json``'s ``metrics``); empty where not computed.
    metrics: dict[str, Any] = field(default_factory=dict)
    #: The 95 % band of the SPD (lower, upper) on ``wavelengths``, peak 1, when the model
    #: has a calibration (the shipped ones do); ``band68`` the same at 68 %.
    band: Optional[tuple[np.ndarray, np.ndarray]] = None
    band68: Optional[tuple[np.ndarray, np.ndarray]] = None
    #: ``"ok"``, ``"doubtful"`` or ``"unusable"``, and why (README: how far to trust an
    #: estimate); ``None`` where the estimate was not judged.
    verdict: Optional[str] = None
    reasons: list[str] = field(default_factory=list)
    #: The GFC estimates of this shape reach (median), from the model's calibration.
    expected_gfc: Optional[float] = None
    #: How many times the bands and metric intervals were widened because the estimated
    #: light explains this photo worse than a typical calibration photo (1: not widened).
    band_widening: Optional[float] = None
    #: Half-widths of the calibrated 68 % and 95 % intervals of the single-number metrics,
    #: by key (``{"cri_ra": {"half68": 1.9, "half95": 4.0}, …}``: Ra 82 ± 4 at 95 %); empty
    #: without a calibration.
    metric_uncertainty: dict[str, dict[str, float]] = field(default_factory=dict)
    #: For photos whose EXIF gives aperture, time and ISO: approximate absolute levels
    #: (``illuminance_lux``, ``ppfd_umol_m2_s``, ``melanopic_edi_lux``,
    #: ``spectral_irradiance_w_m2_nm``, ``note``); ``None`` otherwise, with the reason in
    #: ``json["absolute_reason"]``.
    absolute: Optional[dict[str, Any]] = None
    #: The kind of light the estimate was told of (``light=``; ``"unknown"`` when none).
    light: str = "unknown"
    #: For one of several charts in a photo (:func:`estimate_places`): how the light
    #: compares across the photo's places (``places``, each with ``uv_prime``,
    #: ``grey_uv_prime``, ``cct``, ``duv``, ``relative_illuminance``; ``largest_delta_uv``,
    #: ``greys_largest_delta_uv``, ``most_different``, ``cct_spread_k``, ``duv_spread``,
    #: ``lights_differ``), the same on each of them; ``None`` otherwise.
    across_places: Optional[dict[str, Any]] = None
    #: The library's JSON of the estimate (as ``spdcam estimate --json`` prints it).
    json: dict[str, Any] = field(default_factory=dict, repr=False)

    @staticmethod
    def _from_dict(v: dict[str, Any]) -> "Estimate":
        c = v["colorimetry"]
        return Estimate(
            name=v["name"],
            model=v["model"],
            wavelengths=np.asarray(v["wavelength_nm"], dtype=float),
            spd=np.asarray(v["spd"], dtype=float),
            xy=np.asarray(c["xy"], dtype=float),
            cct=c["cct"],
            duv=c["duv"],
            detection=Detection._from_json(v["photo"]) if v.get("photo") else None,
            metrics=dict(v.get("metrics") or {}),
            band=_band(v.get("band95")),
            band68=_band(v.get("band68")),
            verdict=v.get("verdict"),
            reasons=list(v.get("reasons") or []),
            expected_gfc=v.get("expected_gfc"),
            band_widening=v.get("band_widening"),
            metric_uncertainty=dict(v.get("metric_uncertainty") or {}),
            absolute=v.get("absolute"),
            light=v.get("light", "unknown"),
            across_places=v.get("across_places"),
            json=v,
        )

    def to_colour(self) -> Any:
        """The SPD as a ``colour.SpectralDistribution`` (needs colour-science)."""
        return _to_colour(self.wavelengths, self.spd, self.name)

    def __repr__(self) -> str:
        """The estimate as the command line, the report and the web page show it: the meter's
        headline and the metrics, every number written by the library's one rule."""
        p = self.json.get("presentation")
        if not p:
            return f"Estimate({self.name!r}, xy=({self.xy[0]:.4f}, {self.xy[1]:.4f}))"
        shown = [f"{r['label']} {r['value']}" for r in p["meter"]["headline"]]
        for group in p["groups"]:
            for m in group["metrics"]:
                if m["value"] is not None:
                    unit = f" {m['unit']}" if m["unit"] else ""
                    shown.append(f"{m['label']} {m['value']}{unit}")
                elif (m["not_meaningful"] or "").startswith("not determinable"):
                    # No number, but the interval the photo does support.
                    shown.append(f"{m['label']} {m['not_meaningful']}")
        verdict = f"; verdict {self.verdict}" if self.verdict else ""
        return f"Estimate({self.name!r}: {', '.join(shown)}{verdict})"


def _band(value: Optional[dict[str, Any]]) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """A band of the library's JSON (``{"lower": [...], "upper": [...]}``) as two arrays."""
    if not value:
        return None
    return (np.asarray(value["lower"], dtype=float), np.asarray(value["upper"], dtype=float))


@dataclass(frozen=True)
class Estimates:
    """Estimates for many feature rows, as arrays with one row per estimate."""

    #: The model that made them.
    model: str
    #: The SPDs' wavelengths (nm): shape (wavelengths,).
    wavelengths: np.ndarray
    #: The relative SPDs, peak 1: shape (rows, wavelengths).
    spd: np.ndarray
    #: CIE 1931 2° chromaticities: shape (rows, 2).
    xy: np.ndarray
    #: CCT (K); NaN farther than |Duv| 0.05 from the Planckian locus: shape (rows,).
    cct: np.ndarray
    #: Duv; NaN with CCT: shape (rows,).
    duv: np.ndarray
    #: Each row's judgement as ``spdcam estimate --features --json`` writes it (``verdict``,
    #: ``reasons``, ``self_check``, ``expected_gfc``, ``band_widening``, ``band68``,
    #: ``band95``, ``metric_uncertainty``): one dict per row.
    judgements: list[dict[str, Any]] = field(default_factory=list, repr=False)

    def __len__(self) -> int:
        return self.spd.shape[0]

    @property
    def verdicts(self) -> list[Optional[str]]:
        """Each row's verdict: ``"ok"``, ``"doubtful"`` or ``"unusable"``."""
        return [j.get("verdict") for j in self.judgements]

    def __getitem__(self, i: int) -> Estimate:
        cct, duv = float(self.cct[i]), float(self.duv[i])
        j = self.judgements[i] if self.judgements else {}
        return Estimate(
            name=f"estimate_{range(len(self))[i] + 1}",
            model=self.model,
            wavelengths=self.wavelengths,
            spd=self.spd[i],
            xy=self.xy[i],
            cct=None if np.isnan(cct) else cct,
            duv=None if np.isnan(duv) else duv,
            band=_band(j.get("band95")),
            band68=_band(j.get("band68")),
            verdict=j.get("verdict"),
            reasons=list(j.get("reasons") or []),
            expected_gfc=j.get("expected_gfc"),
            band_widening=j.get("band_widening"),
            metric_uncertainty=dict(j.get("metric_uncertainty") or {}),
        )

    def to_colour(self) -> Any:
        """The SPDs as a ``colour.MultiSpectralDistributions`` (needs colour-science)."""
        try:
            import colour
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_colour() needs colour-science: pip install colour-science") from e
        labels = [f"estimate_{i + 1}" for i in range(len(self))]
        return colour.MultiSpectralDistributions(
            self.spd.T, self.wavelengths, labels=labels, name=self.model
        )

    def to_pandas(self) -> Any:
        """The SPDs as a pandas DataFrame: one row per estimate, one column per wavelength."""
        import pandas as pd

        return pd.DataFrame(
            self.spd,
            columns=[f"{w:g}" for w in self.wavelengths],
            index=[f"estimate_{i + 1}" for i in range(len(self))],
        )


def read_photo(path: Union[str, "os.PathLike[str]"]) -> np.ndarray:
    """The photo file at ``path`` decoded as spdcam decodes it (JPEG, PNG, TIFF; EXIF
    orientation applied): an H×W×3 array of encoded sRGB, uint8 or uint16 as stored. For a
    camera raw file, the upright preview the chart is found in (one pixel per colour-filter
    tile, white-balanced as shot); its patches are read on the raw mosaic itself."""
    width, height, bits, data = _native.read_photo(os.fspath(path))
    dtype = np.uint8 if bits == 8 else np.uint16
    return np.frombuffer(data, dtype=dtype).reshape(height, width, 3)


def _pixels(array: np.ndarray, source: str) -> np.ndarray:
    """An H×W×3 array as C-contiguous uint8 or uint16 (floats 0–1 → 16 bits)."""
    a = np.asarray(array)
    if a.ndim != 3 or a.shape[2] != 3:
        raise SpdcamError(f"{source}: an H×W×3 RGB array is needed; the array has shape {a.shape}")
    if a.dtype == np.uint8 or a.dtype == np.uint16:
        return np.ascontiguousarray(a)
    if np.issubdtype(a.dtype, np.floating):
        if not np.all(np.isfinite(a)):
            raise SpdcamError(f"{source}: the array holds values that are not finite numbers")
        lo, hi = float(a.min()), float(a.max())
        if lo < 0.0 or hi > 1.0:
            raise SpdcamError(
                f"{source}: float pixels must be encoded sRGB in 0–1; the array spans {lo:g}…{hi:g}"
            )
        return np.ascontiguousarray(np.rint(a * 65535.0).astype(np.uint16))
    raise SpdcamError(
        f"{source}: pixels must be uint8, uint16 or float (0–1); the array is {a.dtype}"
    )


def _native_photo(photo: PhotoLike, source: Optional[str]) -> tuple[Any, str]:
    """``photo`` as the native module takes it, and the name messages give it."""
    if isinstance(photo, (bytes, bytearray, memoryview)):
        return bytes(photo), source or "photo bytes"
    if isinstance(photo, np.ndarray):
        name = source or "photo array"
        pixels = _pixels(photo, name)
        h, w, _ = pixels.shape
        return (pixels.tobytes(), w, h, 8 if pixels.dtype == np.uint8 else 16), name
    if isinstance(photo, (str, os.PathLike)):
        name = os.fspath(photo)
        if not os.path.isfile(name):
            raise FileNotFoundError(
                f"{name}: unusable photo: no such file or folder: check the path's spelling"
            )
        return name, name
    raise TypeError(
        "a photo is a path, the bytes of a JPEG/PNG/TIFF file, or an H×W×3 numpy array; "
        f"got {type(photo).__name__}"
    )


def _estimate_all(
    photos: Sequence[PhotoLike],
    models: "_native.Models",
    chart: Optional[str],
    corners: Optional[list[tuple[float, float]]],
    range: str,
    source: Optional[str],
    light: str,
    report: Optional[Progress] = None,
) -> list[Estimate]:
    """The photos estimated in one native call: several at once on every core, without the
    GIL, handed back as dicts (no JSON text between the library and Python)."""
    native = [_native_photo(p, source) for p in photos]
    values = _native.estimate_photos(
        [n[0] for n in native],
        [n[1] for n in native],
        models,
        chart,
        corners,
        range,
        light,
        report,
    )
    return [Estimate._from_dict(v) for v in values]


def _corners(corners: Optional[Iterable[Sequence[float]]]) -> Optional[list[tuple[float, float]]]:
    if corners is None:
        return None
    points = [tuple(float(v) for v in p) for p in corners]
    if len(points) != 4 or any(len(p) != 2 for p in points):
        raise SpdcamError("corners needs four points (x, y): x1,y1,x2,y2,x3,y3,x4,y4")
    return [(p[0], p[1]) for p in points]


def estimate(
    photo: Union[PhotoLike, Sequence[PhotoLike]],
    *,
    chart: Optional[str] = None,
    corners: Optional[Iterable[Sequence[float]]] = None,
    range: str = DEFAULT_RANGE,
    model: Union[Model, str, "os.PathLike[str]", None] = None,
    source: Optional[str] = None,
    progress: Union[bool, Progress, None] = None,
    light: str = "unknown",
) -> Union[Estimate, list[Estimate]]:
    """Estimates the light from a photo of a colour chart, as ``spdcam estimate PHOTO``.

    ``photo`` is a path, the bytes of a JPEG/PNG/TIFF or camera raw file (DNG, CR2, CR3,
    NEF, ARW, RAF, …), or an H×W×3 array of encoded sRGB (uint8, uint16, or float in 0–1);
    a list of them gives a list of estimates.
    ``chart`` looks only for that chart; ``corners`` gives the chart's four outer corners
    in pixels (any order) instead of detecting it; ``range`` is the output grid
    ``START-END[:STEP]`` in nm; ``model`` a :class:`Model` or a ``.spdm`` path (default:
    the shipped models); ``source`` names in-memory photos in messages; ``light`` the kind
    of light, when known (one of :data:`LIGHT_KINDS`: ``"daylight"``, ``"incandescent"``,
    ``"fluorescent"``, ``"white-led"``, ``"hid"``, ``"rgb-led"``, ``"luminaire"``; default
    ``"unknown"``), which keeps the estimate among lights of that kind. For lists,
    ``progress`` is a callback ``(done, total)``, or ``True`` for a tqdm bar (when tqdm is
    installed; it is told after each batch of photos, estimated several at once on every
    core). The work runs without the GIL. Raises :class:`SpdcamError` (a
    ``ValueError``) with the command line's message when the photo cannot be used. Where a
    photo shows several charts, this reads the one found best; :func:`estimate_places`
    reads every one.
    """
    models = _models(model)
    points = _corners(corners)
    if isinstance(photo, (list, tuple)):
        report = _reporter(progress, False, "spdcam")
        try:
            return _estimate_all(photo, models, chart, points, range, source, light, report)
        finally:
            if isinstance(report, _Bar):
                report.close()
    return _estimate_all([photo], models, chart, points, range, source, light)[0]


def estimate_places(
    photo: PhotoLike,
    *,
    chart: Optional[str] = None,
    corners: Optional[Iterable[Iterable[Sequence[float]]]] = None,
    range: str = DEFAULT_RANGE,
    model: Union[Model, str, "os.PathLike[str]", None] = None,
    source: Optional[str] = None,
    light: str = "unknown",
) -> list[Estimate]:
    """The light at every chart one photo shows, as ``spdcam estimate PHOTO`` gives it for a
    photo of several charts: one :class:`Estimate` per chart, numbered from left to right
    (``detection.place``), each carrying the comparison across the photo's places
    (``across_places``: do the lights differ in colour, their CCT and Duv spread, each
    place's light level against the brightest). A photo of one chart gives a list of one,
    the estimate :func:`estimate` gives. ``corners``, when given, places the charts instead
    of detecting them: one set of four outer corners (x, y) per chart, in any order (as
    ``--corners`` given once per chart). ``photo`` and the other arguments are as for
    :func:`estimate`; a chart whose patches are refused is left out, and a photo that gives
    no estimate raises :class:`SpdcamError`.
    """
    models = _models(model)
    native, name = _native_photo(photo, source)
    points = None
    if corners is not None:
        points = [point for one in corners for point in (_corners(one) or [])]
        if not points:
            raise SpdcamError("corners needs one set of four points (x, y) per chart")
    values = _native.estimate_places(native, name, models, chart, points, range, light)
    return [Estimate._from_dict(v) for v in values]


class _Bar:
    """A tqdm bar fed ``(done, total)``, opened at the first report (tqdm is optional)."""

    def __init__(self, tqdm: Any, desc: str) -> None:
        self._tqdm, self._desc, self._bar = tqdm, desc, None

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None:
            self._bar = self._tqdm(total=total, desc=self._desc)
        self._bar.total = total
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def _reporter(progress: Union[bool, Progress, None], default: bool, desc: str) -> Optional[Any]:
    """The ``(done, total)`` callback ``progress`` asks for: itself when callable, a tqdm
    bar when ``True`` (or ``None`` with ``default``) and tqdm is installed, else ``None``."""
    if callable(progress):
        return progress
    if progress or (progress is None and default):
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return None
        return _Bar(tqdm, desc)
    return None


def _run(progress: Union[bool, Progress, None], desc: str, work: Callable[[Any], Any]) -> Any:
    """``work(callback)`` with the callback ``progress`` asks for (a tqdm bar by default);
    the bar is closed when the work ends."""
    report = _reporter(progress, True, desc)
    try:
        return work(report)
    finally:
        if isinstance(report, _Bar):
            report.close()


def estimate_features(
    features: Any,
    names: Optional[Sequence[str]] = None,
    *,
    range: str = DEFAULT_RANGE,
    model: Union[Model, str, "os.PathLike[str]", None] = None,
    source: str = "features",
    light: str = "unknown",
) -> Estimates:
    """Estimates the light for chart feature rows, as ``spdcam estimate --features``.

    ``features`` is a 2-D array (rows × columns; one row is one estimate, values on any
    scale, e.g. 0–255), a 1-D array for one row, or a pandas DataFrame whose columns name
    the features. ``names`` are the columns (``p01_r, p01_g, …``); by default the columns of
    the model that reads that many. Returns :class:`Estimates` (arrays over the rows), each
    row judged as the command line judges it (verdict, reasons, bands, expected GFC);
    ``light`` as for :func:`estimate`.
    """
    if names is None and hasattr(features, "columns") and hasattr(features, "to_numpy"):
        names = [str(c) for c in features.columns]
        features = features.to_numpy()
    a = np.asarray(features)
    if a.ndim == 1:
        a = a[np.newaxis, :]
    if a.ndim != 2 or a.shape[0] == 0 or a.shape[1] == 0:
        raise SpdcamError(f"{source}: a rows × features array is needed; the shape is {a.shape}")
    if not np.issubdtype(a.dtype, np.number) or np.issubdtype(a.dtype, np.complexfloating):
        raise SpdcamError(f"{source}: features must be real numbers; the array is {a.dtype}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    rows, cols = a.shape
    if names is not None:
        names = [str(n) for n in names]
        if len(names) != cols:
            raise SpdcamError(f"{source}: {len(names)} names for {cols} feature columns")
    model_name, wl, spd, xy, cct, duv, judged = _native.estimate_rows(
        a.tobytes(), rows, _models(model), names, source, range, light
    )
    wavelengths = np.frombuffer(wl, dtype=np.float64)
    return Estimates(
        model=model_name,
        wavelengths=wavelengths,
        spd=np.frombuffer(spd, dtype=np.float64).reshape(rows, wavelengths.size),
        xy=np.frombuffer(xy, dtype=np.float64).reshape(rows, 2),
        cct=np.frombuffer(cct, dtype=np.float64),
        duv=np.frombuffer(duv, dtype=np.float64),
        judgements=judged,
    )


@dataclass(frozen=True)
class Rendering:
    """A chart rendered under a light by a simulated camera."""

    #: The rendered chart, encoded sRGB 0–1: shape (height, width, 3), float32.
    image: np.ndarray
    #: The feature columns, ``p01_r, p01_g, …``.
    feature_names: list[str]
    #: The feature row (mean encoded sRGB 0–255 of each feature patch), as a model reads it.
    features: np.ndarray

    def to_uint8(self) -> np.ndarray:
        """The image as 8-bit sRGB, as ``spdcam render`` writes it to PNG."""
        return np.rint(np.clip(self.image, 0.0, 1.0) * 255.0).astype(np.uint8)


def render(
    spd: Any,
    wavelengths: Optional[Sequence[float]] = None,
    *,
    camera: str = "nikon_d5100_npl",
    chart: Optional[str] = None,
    patch_px: int = 24,
    seed: int = 0,
) -> Rendering:
    """Renders a chart photographed under a light, as ``spdcam render`` with its default
    camera settings: the same light and seed give the same image and features.

    ``spd`` names a light (``"D65"``, ``"A"``, ``"cct:4000"``, ``"daylight:5000"``,
    ``"planck:3000"``, a spectral CSV path), or is its values on ``wavelengths`` (nm), or a
    ``colour.SpectralDistribution``. ``camera`` and ``chart`` are built-in names (``spdcam
    list``; :func:`charts`) or CSV files; ``chart`` by default the command line's,
    ``_native.DEFAULT_CHART`` (the ColorChecker 24).
    """
    if hasattr(spd, "wavelengths") and hasattr(spd, "values") and wavelengths is None:
        wavelengths, spd = spd.wavelengths, spd.values
    if isinstance(spd, (str, os.PathLike)):
        if wavelengths is not None:
            raise SpdcamError("wavelengths go with SPD values, not with a named light")
        args: tuple = (os.fspath(spd), None, None)
    else:
        values = np.asarray(spd, dtype=np.float64).ravel()
        if wavelengths is None:
            raise SpdcamError("SPD values need their wavelengths (nm)")
        wl = np.asarray(wavelengths, dtype=np.float64).ravel()
        if wl.size != values.size:
            raise SpdcamError(f"{wl.size} wavelengths for {values.size} SPD values")
        args = ("light", wl.tolist(), values.tolist())
    width, height, data, names, features = _native.render(
        *args, camera=camera, chart=chart, patch_px=patch_px, seed=seed
    )
    return Rendering(
        image=np.frombuffer(data, dtype=np.float32).reshape(height, width, 3),
        feature_names=list(names),
        features=np.asarray(features, dtype=np.float32),
    )


def _optional(module: str, what: str) -> Any:
    """Imports an optional dependency, or says which package ``what`` needs."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        package = module.split(".")[0]
        raise ImportError(f"{what} needs {package}: pip install {package}") from e


@dataclass(frozen=True)
class Dataset:
    """A dataset directory as ``spdcam generate`` writes it: ``manifest.json`` (every
    setting, the columns, the files) and ``samples/part-NNNNN.parquet`` (one row per sample:
    ``sample``, ``family``, the features ``p01_r…``, the SPD ``spd_380…``, …)."""

    #: The directory.
    path: str

    @property
    def manifest(self) -> dict[str, Any]:
        """The dataset's manifest (``manifest.json``)."""
        with open(os.path.join(self.path, "manifest.json"), encoding="utf-8") as f:
            return json.load(f)

    def __len__(self) -> int:
        return int(self.manifest["samples"])

    def to_arrow(self) -> Any:
        """The samples as one ``pyarrow.Table``, in sample order (needs pyarrow)."""
        pq = _optional("pyarrow.parquet", "to_arrow()")
        pa = _optional("pyarrow", "to_arrow()")
        files = [os.path.join(self.path, f["name"]) for f in self.manifest["files"]]
        return pa.concat_tables([pq.read_table(f) for f in files])

    def to_pandas(self) -> Any:
        """The samples as a pandas DataFrame, in sample order (needs pandas and pyarrow)."""
        _optional("pandas", "to_pandas()")
        return self.to_arrow().to_pandas()


def generate(
    output: PathLike,
    lighting: str,
    count: int,
    *,
    seed: int = 0,
    chart: Optional[str] = None,
    camera: str = "nikon_d5100_npl",
    spd_grid: str = "380-780:5",
    fast: bool = False,
    randomise: Union[str, Sequence[str], None] = None,
    cameras: Union[str, Sequence[str], None] = None,
    force: bool = False,
    progress: Union[bool, Progress, None] = None,
) -> Dataset:
    """Generates a dataset of (features, SPD) samples from the virtual camera into the
    directory ``output``, as ``spdcam generate --lighting LIGHTING --count COUNT --output
    OUTPUT`` with the same options does: the same library run writes the same files.

    ``lighting`` is a lighting recipe (``spdcam list lighting`` shows the forms); sample
    ``i`` depends only on ``(seed, i)``. ``chart`` and ``camera`` are built-in names or CSV
    files (``chart`` by default the ColorChecker 24, as :func:`render`; the camera's other
    settings are the command line's defaults); ``spd_grid`` the
    wavelengths the SPDs are stored at, ``START-END[:STEP]`` in nm; ``fast`` gives
    noise-free patch-level features without an image; ``randomise`` the domain
    randomisation groups (camera, exposure, wb, tone, jpeg, gradient) and ``cameras`` the
    cameras ``camera`` draws from (a directory or names). An existing run in ``output`` is
    resumed; ``force`` replaces it. ``progress`` is a callback ``(samples done, total)``;
    by default a tqdm bar when tqdm is installed, ``False`` for none. The work runs without
    the GIL. Raises :class:`SpdcamError` with the command line's message on bad input.
    """
    groups = [randomise] if isinstance(randomise, str) else list(randomise or [])
    pool = cameras if cameras is None or isinstance(cameras, str) else ",".join(cameras)
    path = os.fspath(output)
    _run(
        progress,
        "samples",
        lambda report: _native.generate(
            path,
            lighting,
            max(int(count), 0),
            seed=seed,
            chart=chart,
            camera=camera,
            spd_grid=spd_grid,
            fast=fast,
            randomise=[g for group in groups for g in group.split(",")],
            cameras=pool,
            force=force,
            progress=report,
        ),
    )
    return Dataset(path)


def _dataset_dir(data: Union[Dataset, PathLike]) -> str:
    return data.path if isinstance(data, Dataset) else os.fspath(data)


#: Whether this build trains: ``train`` and ``finetune`` need the training stack (burn),
#: which a plain ``pip install ./python`` leaves out so that it installs in minutes.
CAN_TRAIN: bool = hasattr(_native, "train")

#: How to install the build that trains, as the error of :func:`train` says it.
TRAIN_INSTALL = 'pip install ./python --config-settings=build-args="--features train"'


def _require_training(what: str) -> None:
    """Raises the ImportError naming the install that trains, in a build without training."""
    if not CAN_TRAIN:
        raise ImportError(
            f"spdcam.{what}() needs the training build of spdcam (burn), which this install "
            f"leaves out; reinstall from the repository root with: {TRAIN_INSTALL}"
        )


def train(
    data: Union[Dataset, PathLike],
    output: PathLike,
    model: str = "cnn1d",
    *,
    epochs: Optional[int] = None,
    seed: int = 1,
    progress: Union[bool, Progress, None] = None,
) -> Model:
    """Trains a model on a dataset directory (or :class:`Dataset`) and writes it to
    ``output`` (``.spdm``), as ``spdcam train --data DATA --model MODEL --output OUTPUT``:
    ``model`` is ``"cnn1d"`` (the thesis's 1D CNN), ``"mlp"`` (its DNN) or ``"linear"``
    (ridge regression); the default schedule, ``epochs`` overriding its count; ``seed`` for
    the split, weights and shuffling. Returns the model loaded from ``output``.

    ``progress`` is a callback ``(epochs done, epochs)``; by default a tqdm bar when tqdm
    is installed, ``False`` for none. The work runs without the GIL. Raises
    :class:`SpdcamError` with the command line's message on bad input, and ImportError in a
    build without training (:data:`CAN_TRAIN`).
    """
    _require_training("train")
    out = os.fspath(output)
    native = _run(
        progress,
        "epochs",
        lambda report: _native.train(
            _dataset_dir(data), out, model, epochs=epochs, seed=seed, progress=report
        ),
    )
    return Model(native)


def finetune(
    model: PathLike,
    data: Union[Dataset, PathLike],
    output: PathLike,
    *,
    epochs: Optional[int] = None,
    freeze: bool = False,
    refit_pca: bool = False,
    keep_output: bool = False,
    seed: int = 1,
    progress: Union[bool, Progress, None] = None,
) -> Model:
    """Fine-tunes the model file ``model`` on a (small) dataset directory, e.g. features
    of one's own photos with their measured SPDs (``spdcam dataset import``), and writes
    ``output``, as ``spdcam finetune --model MODEL --data DATA --output OUTPUT``.

    With none of ``epochs``, ``freeze`` (train only the new output layer), ``refit_pca``
    (a new PCA on the new data) and ``keep_output`` (keep the trained output layer) the
    recipe is chosen by cross-validation on the data, the model unchanged and ridge
    regression on the data alone among the candidates (at least 4 samples); with any of them, the thesis's transfer learning with
    those changes. Returns the model loaded from ``output``.

    ``progress`` is a callback ``(done, total)`` counting the cross-validation's fits, or
    epochs with a recipe given; by default a tqdm bar when tqdm is installed, ``False`` for
    none. The work runs without the GIL. Raises :class:`SpdcamError` with the command
    line's message on bad input, and ImportError in a build without training
    (:data:`CAN_TRAIN`).
    """
    _require_training("finetune")
    out = os.fspath(output)
    native = _run(
        progress,
        "fine-tuning",
        lambda report: _native.finetune(
            os.fspath(model),
            _dataset_dir(data),
            out,
            epochs=epochs,
            freeze=freeze,
            refit_pca=refit_pca,
            keep_output=keep_output,
            seed=seed,
            progress=report,
        ),
    )
    return Model(native)

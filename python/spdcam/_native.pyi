"""Type stub of the compiled part of spdcam (``spdcam._native``); use the ``spdcam`` API."""

from typing import Any, Callable, Optional, Sequence, Union

Progress = Optional[Callable[[int, int], None]]
"""A callback ``(done, total)``, called with the GIL held while long work runs."""

__version__: str
DEFAULT_CHART: str
"""The chart ``render`` and ``generate`` draw when none is named."""

def charts() -> list[tuple[str, str, str]]:
    """``(name, shown name, description)`` of each chart spdcam knows by name."""

def shown_chart_name(name: str) -> str:
    """The name people know the chart called ``name`` by."""

class SpdcamError(ValueError):
    """An input spdcam cannot use; the message is the command line's."""

class Models:
    """A set of models an estimate chooses from by the chart a photo shows."""

    @staticmethod
    def shipped() -> "Models": ...
    @staticmethod
    def load(path: str) -> "Models": ...
    def describe(self) -> list[tuple[str, Optional[str], list[str], str]]: ...

PhotoInput = Union[str, bytes, tuple[bytes, int, int, int]]
"""A photo file's path, an encoded photo's bytes, or ``(pixels, width, height, bits)``."""

def estimate_photos(
    photos: Sequence[PhotoInput],
    sources: Sequence[str],
    models: Models,
    chart: Optional[str] = None,
    corners: Optional[Sequence[tuple[float, float]]] = None,
    range: str = "400-700:5",
    light: str = "unknown",
    progress: Progress = None,
) -> list[dict]:
    """Estimates the light from photos, several at once; each estimate as a dict."""

def estimate_places(
    photo: PhotoInput,
    source: str,
    models: Models,
    chart: Optional[str] = None,
    range: str = "400-700:5",
    light: str = "unknown",
) -> list[dict]:
    """Estimates the light at every chart one photo shows; each estimate as a dict."""

def estimate_rows(
    values: bytes,
    rows: int,
    models: Models,
    names: Optional[Sequence[str]] = None,
    source: str = "features",
    range: str = "400-700:5",
    light: str = "unknown",
) -> tuple[str, bytes, bytes, bytes, bytes, bytes, list[dict]]: ...
def read_photo(path: str) -> tuple[int, int, int, bytes]: ...
def metric_registry() -> list[dict[str, Any]]: ...
def light_kinds() -> list[str]: ...
def library_seconds_photo(path: str, models: Models, repeats: int) -> float: ...
def library_seconds_rows(values: bytes, rows: int, models: Models, repeats: int) -> float: ...
def render(
    spd: str,
    wavelengths: Optional[Sequence[float]] = None,
    values: Optional[Sequence[float]] = None,
    camera: str = "nikon_d5100_npl",
    chart: Optional[str] = None,
    patch_px: int = 24,
    seed: int = 0,
) -> tuple[int, int, bytes, list[str], list[float]]: ...
def generate(
    output: str,
    lighting: str,
    count: int,
    seed: int = 0,
    chart: Optional[str] = None,
    camera: str = "nikon_d5100_npl",
    spd_grid: str = "380-780:5",
    fast: bool = False,
    randomise: Sequence[str] = ...,
    cameras: Optional[str] = None,
    force: bool = False,
    progress: Progress = None,
) -> int:
    """Generates a dataset into ``output`` as ``spdcam generate``; the samples it holds."""

def train(
    data: str,
    output: str,
    model: str = "cnn1d",
    epochs: Optional[int] = None,
    seed: int = 1,
    progress: Progress = None,
) -> Models:
    """Trains a model on a dataset as ``spdcam train``; the model written to ``output``.
    Only in the training build (cargo feature ``train``)."""

def finetune(
    model: str,
    data: str,
    output: str,
    epochs: Optional[int] = None,
    freeze: bool = False,
    refit_pca: bool = False,
    keep_output: bool = False,
    seed: int = 1,
    progress: Progress = None,
) -> Models:
    """Fine-tunes a model file on a dataset as ``spdcam finetune``; the model written.
    Only in the training build (cargo feature ``train``)."""

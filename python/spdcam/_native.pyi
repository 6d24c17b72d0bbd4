"""Type stub of the compiled part of spdcam (``spdcam._native``); use the ``spdcam`` API."""

from typing import Optional, Sequence

__version__: str

class SpdcamError(ValueError):
    """An input spdcam cannot use; the message is the command line's."""

class Models:
    """A set of models an estimate chooses from by the chart a photo shows."""

    @staticmethod
    def shipped() -> "Models": ...
    @staticmethod
    def load(path: str) -> "Models": ...
    def describe(self) -> list[tuple[str, Optional[str], list[str], str]]: ...

def estimate_file(
    path: str,
    models: Models,
    chart: Optional[str] = None,
    corners: Optional[Sequence[tuple[float, float]]] = None,
    range: str = "400-700:5",
) -> str: ...
def estimate_encoded(
    data: bytes,
    source: str,
    models: Models,
    chart: Optional[str] = None,
    corners: Optional[Sequence[tuple[float, float]]] = None,
    range: str = "400-700:5",
) -> str: ...
def estimate_pixels(
    pixels: bytes,
    width: int,
    height: int,
    bits: int,
    source: str,
    models: Models,
    chart: Optional[str] = None,
    corners: Optional[Sequence[tuple[float, float]]] = None,
    range: str = "400-700:5",
) -> str: ...
def estimate_rows(
    values: bytes,
    rows: int,
    models: Models,
    names: Optional[Sequence[str]] = None,
    source: str = "features",
    range: str = "400-700:5",
) -> tuple[str, bytes, bytes, bytes, bytes, bytes]: ...
def read_photo(path: str) -> tuple[int, int, int, bytes]: ...
def library_seconds_photo(path: str, models: Models, repeats: int) -> float: ...
def library_seconds_rows(values: bytes, rows: int, models: Models, repeats: int) -> float: ...
def render(
    spd: str,
    wavelengths: Optional[Sequence[float]] = None,
    values: Optional[Sequence[float]] = None,
    camera: str = "nikon_d5100_npl",
    chart: str = "colorchecker24",
    patch_px: int = 24,
    seed: int = 0,
) -> tuple[int, int, bytes, list[str], list[float]]: ...

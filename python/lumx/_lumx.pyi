# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Type stubs of the extension lumx._lumx (python/src/*.cpp). Units: m, degrees, cd (W/sr), lm (W),
# lx (W/m^2); directions in the photometric frame (+X = C0, +Y = C90, -Z = nadir).
import os
from typing import Callable, Iterable, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
abi_namespace: str

ArrayLike = npt.ArrayLike
PathLike = Union[str, os.PathLike[str]]
FloatArray = npt.NDArray[np.float64]
Vec3 = Union[Sequence[float], npt.NDArray[np.floating]]
ChunkLike = Union[np.ndarray, Mapping[str, ArrayLike]]
RaysArgument = Union[PathLike, "RayFile", ChunkLike, Iterable[ChunkLike], Callable[[], Iterable[ChunkLike]]]

class Error(ValueError):
    """Bad input, located: file, line (or None), byte_offset (or None), field, message, severity, finding.
    Failed I/O raises OSError (FileNotFoundError, PermissionError, ...) with the same attributes."""
    file: str
    line: Optional[int]
    byte_offset: Optional[int]
    field: str
    message: str
    severity: str
    finding: Finding

class LumxWarning(UserWarning):
    """A reader's warning, issued through the warnings module; attributes as lumx.Error."""
    file: str
    line: Optional[int]
    byte_offset: Optional[int]
    field: str
    message: str
    severity: str
    finding: Finding

class Finding:
    """One located finding."""
    @property
    def severity(self) -> Literal["error", "warning", "note"]: ...
    @property
    def file(self) -> str: ...
    @property
    def line(self) -> Optional[int]:
        """1-based line of a text file, or None."""
    @property
    def byte_offset(self) -> Optional[int]:
        """Byte offset in a binary file, or None."""
    @property
    def field(self) -> str: ...
    @property
    def message(self) -> str: ...

# ---- photometry

class Spread:
    """Beam (50 %) and field (10 %) angles of one vertical plane."""
    @property
    def beam_deg(self) -> float: ...
    @property
    def field_deg(self) -> float: ...
    @property
    def peak_cd(self) -> float: ...
    @property
    def peak_angle_deg(self) -> float: ...

class Summary:
    """Datasheet figures (what `lumx info` prints)."""
    @property
    def flux_lm(self) -> float: ...
    @property
    def rated_lamp_flux_lm(self) -> float: ...
    @property
    def max_cd(self) -> float: ...
    @property
    def max_horizontal_deg(self) -> float: ...
    @property
    def max_vertical_deg(self) -> float: ...
    @property
    def c0_c180(self) -> Spread: ...
    @property
    def c90_c270(self) -> Spread: ...
    @property
    def downward_fraction(self) -> float:
        """0..1"""
    @property
    def light_output_ratio(self) -> Optional[float]: ...
    @property
    def efficacy_lm_per_w(self) -> float: ...

class LampSet:
    @property
    def count(self) -> int: ...
    @property
    def type(self) -> str: ...
    @property
    def flux_lm(self) -> float: ...
    @property
    def color(self) -> str: ...
    @property
    def cri(self) -> str: ...
    @property
    def watts(self) -> float: ...

class Photometry:
    """Far-field photometry (IES LM-63 or EULUMDAT)."""
    @property
    def type(self) -> Literal["A", "B", "C"]: ...
    @property
    def symmetry(self) -> str: ...
    @property
    def horizontal_deg(self) -> FloatArray:
        """Stored horizontal angles, degrees: a live view (no copy)."""
    @property
    def vertical_deg(self) -> FloatArray:
        """Stored vertical angles, degrees: a live view (no copy)."""
    @property
    def candela(self) -> FloatArray:
        """Stored intensities, cd, shape (len(horizontal_deg), len(vertical_deg)): a live view."""
    @property
    def flux_lm(self) -> float:
        """Luminous flux, lm: the exact integral of the bilinear full-sphere table."""
    @overload
    def intensity(self, directions: Vec3) -> float: ...
    @overload
    def intensity(self, directions: ArrayLike) -> FloatArray:
        """Intensity, cd, towards each direction of an (N, 3) array -> (N,)."""
    def intensity_at(self, horizontal_deg: ArrayLike, vertical_deg: ArrayLike) -> Union[float, FloatArray]:
        """Intensity, cd, at photometric angles (degrees) of the photometry's own type."""
    def polar_curve(self, plane: str = "C0-C180", step_deg: float = 0.5) -> Tuple[FloatArray, FloatArray]:
        """(theta_deg from -180 to 180, cd) in the plane 'C0-C180' or 'C90-C270'."""
    def summary(self) -> Summary: ...
    def ugr_table(self, *, spacing_to_height: float = 0.25, height_m: float = 2.0) -> dict[str, object]:
        """The CIE 117/190 UGR table: 'crosswise' and 'endwise' (19 × 5 arrays), rooms, reflectances, flux."""
    def validate(self) -> list[Finding]: ...
    def write(self, path: str, ies_version: int = 2019, digits: int = 7, expand_c90_c270: bool = False) -> None:
        """Writes .ies or .ldt (by extension), atomically."""
    @property
    def absolute(self) -> bool: ...
    @property
    def lamps(self) -> list[LampSet]: ...
    @property
    def ballast_factor(self) -> float: ...
    @property
    def input_watts(self) -> float:
        """W"""
    @property
    def keywords(self) -> list[Tuple[str, str]]: ...
    @property
    def opening(self) -> dict[str, Union[float, str]]:
        """width_m, length_m, height_m (signed, m) and shape."""
    @property
    def file(self) -> str: ...
    @property
    def format(self) -> Literal["IES", "EULUMDAT"]: ...
    @property
    def version(self) -> str: ...

def read_photometry(path: str) -> Photometry:
    """Reads IES LM-63 or EULUMDAT. Raises lumx.Error (located) or OSError; warns lumx.LumxWarning."""

def check(path: str) -> list[Finding]:
    """Findings for a photometry file, a rayset or a bundle folder (as `lumx check`); empty = OK."""

# ---- raysets

class RaysetInfo:
    @property
    def file(self) -> str: ...
    @property
    def format(self) -> str: ...
    @property
    def version(self) -> str: ...
    @property
    def ray_count(self) -> int: ...
    @property
    def quantity(self) -> Literal["photometric", "radiometric"]: ...
    @property
    def flux_unit(self) -> Literal["lm", "W"]: ...
    @property
    def header_flux(self) -> Optional[float]:
        """lm or W, as the header states it (never applied)."""
    @property
    def source_length_unit(self) -> str: ...
    @property
    def wavelength_nm(self) -> Optional[float]: ...
    @property
    def spectra(self) -> list[Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]]: ...
    @property
    def text(self) -> dict[str, str]: ...
    @property
    def values(self) -> dict[str, float]: ...
    @property
    def simulated(self) -> bool: ...

class RayFile:
    """An open rayset; iterating yields structured arrays (position m, direction, flux lm or W)."""
    @property
    def info(self) -> RaysetInfo: ...
    @property
    def chunk_rays(self) -> int: ...
    def next_chunk(self) -> Optional[np.ndarray]: ...
    def rewind(self) -> None: ...
    def close(self) -> None: ...
    def __iter__(self) -> RayFile: ...
    def __next__(self) -> np.ndarray: ...
    def __enter__(self) -> RayFile: ...
    def __exit__(self, *args: object) -> None: ...
    def summary(self) -> dict[str, object]:
        """rays, flux_sum (lm or W), lo, hi, center (m), radius (m), zero_flux_rays."""
    def read_all(self, max_rays: int) -> np.ndarray: ...

def ray_dtype(wavelength: bool = False) -> np.dtype: ...
def open_rays(path: str, chunk_rays: int = 65536, flux: Literal["auto", "luminous", "radiant"] = "auto",
              format: Optional[str] = None) -> RayFile: ...
def write_tm25(path: str, rays: RaysArgument, quantity: Optional[Literal["photometric", "radiometric"]] = None,
               header_flux: Optional[float] = None, text: Mapping[str, str] = ..., wavelength_nm: Optional[float] = None,
               chunk_rays: int = 65536) -> None: ...

# ---- bundles

class Level:
    """One loaded APL level."""
    @property
    def index(self) -> int: ...
    @property
    def apl_count(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def map_resolution(self) -> int: ...
    @property
    def map_frame(self) -> npt.NDArray[np.float32]:
        """(3, 3) rotation: the maps are read at map_frame @ w for a photometric direction w"""
    @property
    def positions(self) -> npt.NDArray[np.float32]:
        """(N, 3), m"""
    @property
    def flux(self) -> FloatArray:
        """(N, 3), lm or W per channel"""
    @property
    def parent(self) -> npt.NDArray[np.int32]: ...
    @property
    def error_table(self) -> Tuple[FloatArray, FloatArray]:
        """(relative distance, relative RMSE)"""
    @property
    def map_bytes(self) -> int: ...
    def map(self, apl: int) -> npt.NDArray[np.float32]:
        """(R, 2R, channels) read-only view, cd or W/sr, drawn in map_frame."""
    def maps(self) -> npt.NDArray[np.float32]:
        """(N, R, 2R, channels) copy, cd or W/sr, drawn in map_frame."""
    def intensity(self, directions: ArrayLike, rgb: bool = False) -> Union[float, FloatArray]:
        """Far-field intensity of the level, cd or W/sr."""
    def sample_emission(self, u: ArrayLike) -> np.ndarray:
        """Structured array: apl, position (3,) m, direction (3,), pdf_apl, pdf_direction (1/sr), flux (3,)."""
    def pdf(self, apl: ArrayLike, directions: ArrayLike) -> Union[float, FloatArray]:
        """Joint density of emission sampling, 1/sr."""
    def choose_light(self, points: ArrayLike, normals: ArrayLike, u: ArrayLike) -> Tuple[npt.NDArray[np.int64], FloatArray]: ...

class RadianceVolume:
    @property
    def counts(self) -> Tuple[int, int, int]: ...
    @property
    def lo(self) -> Tuple[float, float, float]:
        """m"""
    @property
    def hi(self) -> Tuple[float, float, float]:
        """m"""
    @property
    def voxel_size(self) -> float:
        """m"""
    @property
    def bands(self) -> int: ...
    @property
    def channels(self) -> int: ...
    @property
    def coefficients(self) -> npt.NDArray[np.float32]:
        """(nz, ny, nx, channels, bands^2) read-only view."""
    def radiance(self, points: ArrayLike, directions: ArrayLike) -> FloatArray:
        """(N, 3): flux unit per m^2 sr (cd/m^2 for lm)."""

class Bundle:
    """A lumx bundle folder; opening reads manifest.json only."""
    def __init__(self, path: str) -> None: ...
    @property
    def path(self) -> str: ...
    @property
    def quantity(self) -> Literal["photometric", "radiometric"]: ...
    @property
    def channels(self) -> Literal["luminance", "rgb"]: ...
    @property
    def intensity_unit(self) -> str: ...
    @property
    def flux_unit(self) -> str: ...
    @property
    def irradiance_unit(self) -> str: ...
    @property
    def bounds(self) -> Tuple[Tuple[float, float, float], float]:
        """((x, y, z), radius), m"""
    @property
    def provenance(self) -> dict[str, str]: ...
    @property
    def generator(self) -> str: ...
    @property
    def level_count(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def apl_counts(self) -> list[int]: ...
    @property
    def map_resolutions(self) -> list[list[int]]: ...
    def level_flux(self, level: Optional[int] = None) -> float:
        """lm or W, from the manifest."""
    def level_positions(self, level: Optional[int] = None) -> npt.NDArray[np.float32]:
        """(N, 3), m, from the manifest."""
    @property
    def has_volume(self) -> bool: ...
    @property
    def bytes_read(self) -> int: ...
    @property
    def total_bytes(self) -> int: ...
    @property
    def attachments(self) -> list[str]: ...
    def read_attachment(self, name: str) -> bytes: ...
    def load_level(self, level: int, max_resolution: int = 0) -> Level: ...
    def level(self, level: Optional[int] = None) -> Level: ...
    def irradiance(self, points: ArrayLike, normals: Optional[ArrayLike] = None, *, level: Optional[int] = None,
                   lod: Optional[bool] = None, error_target: Optional[float] = None, u: Optional[ArrayLike] = None,
                   seed: int = 1, rgb: bool = False, min_distance: float = 0.0) -> Union[float, FloatArray]:
        """Irradiance, lx or W/m^2, at (N, 3) points (m) with (N, 3) normals."""
    def intensity(self, directions: ArrayLike, *, level: Optional[int] = None, rgb: bool = False) -> Union[float, FloatArray]:
        """Far-field intensity, cd or W/sr."""
    def sample_emission(self, u: ArrayLike, *, level: Optional[int] = None) -> np.ndarray:
        """Level.sample_emission on a level (default the finest)."""
    def pdf(self, apl: ArrayLike, directions: ArrayLike, *, level: Optional[int] = None) -> Union[float, FloatArray]:
        """Level.pdf on a level (default the finest), 1/sr."""
    def load_volume(self) -> RadianceVolume: ...

def direction_to_uv(directions: ArrayLike) -> FloatArray:
    """(u, v) of directions in a sphere map's own frame (a level's: Level.map_frame @ w)"""
def uv_to_direction(uv: ArrayLike) -> FloatArray:
    """directions, in the sphere map's own frame, of (u, v) (photometric: Level.map_frame.T @ m)"""

# ---- building

class BuildResult:
    @property
    def bundle(self) -> str: ...
    @property
    def apl_counts(self) -> list[int]: ...
    @property
    def map_resolutions(self) -> list[int]: ...
    @property
    def built_resolutions(self) -> list[int]: ...
    @property
    def rays(self) -> int: ...
    @property
    def seeds(self) -> int: ...
    @property
    def bytes(self) -> int: ...
    @property
    def clustered_by_line(self) -> bool: ...
    @property
    def point_sources(self) -> int: ...
    @property
    def error_tables(self) -> bool: ...
    @property
    def far_field_flux_lm(self) -> float: ...
    @property
    def seconds(self) -> float: ...

def build(rays: RaysArgument, out: str, *, levels: Sequence[int] = (1, 8, 64, 256, 512), seeds: int = 250000,
          map_resolution: int = 0, rays_per_texel: float = 8.0, patches: int = 16, evaluate: bool = True,
          c_step_deg: float = 2.5, gamma_step_deg: float = 1.0, efficacy_lm_per_w: float = 0.0,
          converge: bool = True, cluster_by: Literal["auto", "start", "line"] = "auto",
          resolution_exponent: float = 0.0, smooth: float = 0.0, point_sources: bool = True, threads: int = 0,
          progress: Optional[Callable[[float, str], object]] = None) -> BuildResult:
    """Rays in, a bundle out, as `lumx build` makes it; the GIL is released while it works."""

# ---- baking

class BakePass:
    @property
    def particles(self) -> int: ...
    @property
    def exits(self) -> int: ...
    @property
    def seconds(self) -> float: ...
    @property
    def error(self) -> float: ...
    @property
    def error_estimate(self) -> float: ...
    @property
    def far_field_error(self) -> float: ...
    @property
    def level_error(self) -> list[float]: ...

class BakeResult:
    @property
    def bundle(self) -> str: ...
    @property
    def particles(self) -> int: ...
    @property
    def exits(self) -> int: ...
    @property
    def emitted_lm(self) -> float: ...
    @property
    def exited_lm(self) -> float: ...
    @property
    def seconds(self) -> float: ...
    @property
    def passes(self) -> list[BakePass]: ...
    @property
    def target_met(self) -> bool: ...
    @property
    def stopped_by(self) -> str: ...
    @property
    def apl_counts(self) -> list[int]: ...
    @property
    def map_resolutions(self) -> list[int]: ...
    @property
    def error_tables(self) -> bool: ...
    @property
    def far_field_flux_lm(self) -> float: ...
    @property
    def bytes(self) -> int: ...
    @property
    def luminaire_sha256(self) -> str: ...

def bake(luminaire: PathLike, out: PathLike, *, particles: int = 1000000, target_error: float = 0.05,
         target_distance: float = 1.0, time_limit_s: float = 0.0, pass_particles: int = 0, seed: int = 1,
         threads: int = 0, levels: Sequence[int] = (1, 8, 64, 256, 512), volume_voxels: int = 32768,
         max_depth: int = 256, rays_out: str = "", evaluate: bool = True,
         progress: Optional[Callable[[float, str], object]] = None) -> BakeResult:
    """A glTF luminaire traced into a bundle, as `lumx bake` makes it; the GIL is released while it works."""

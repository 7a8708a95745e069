# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""lumx: luminaire photometry, raysets and APL bundles, with NumPy arrays.

Units throughout: lengths in metres, angles in degrees, intensity in cd (W/sr for radiometric data),
flux in lm (W), irradiance in lx (W/m^2). Directions are in the luminaire's photometric frame:
+X = C0, +Y = C90, -Z = nadir.

    import lumx
    p = lumx.read_photometry("downlight.ies")        # lumx.Error (a ValueError) locates bad input
    p.flux_lm, p.intensity([[0, 0, -1], [1, 0, -1]])  # lm; cd per direction, computed in C++
    b = lumx.Bundle("lamp.lumx")                     # reads manifest.json only
    b.irradiance(points, normals, level=2)           # lx at (N, 3) points, GIL released

docs/python.md is the guide; every function's docstring states its units.
"""
from ._lumx import (  # noqa: F401  (the public API, re-exported)
    __version__,
    abi_namespace,
    Error,
    LumxWarning,
    Finding,
    Photometry,
    Summary,
    Spread,
    LampSet,
    read_photometry,
    check,
    RaysetInfo,
    RayFile,
    open_rays,
    ray_dtype,
    write_tm25,
    Bundle,
    Level,
    RadianceVolume,
    direction_to_uv,
    uv_to_direction,
    BuildResult,
    build,
    BakePass,
    BakeResult,
    bake,
)

__all__ = [
    "Error", "LumxWarning", "Finding",
    "Photometry", "Summary", "Spread", "LampSet", "read_photometry", "check",
    "RaysetInfo", "RayFile", "open_rays", "ray_dtype", "write_tm25",
    "Bundle", "Level", "RadianceVolume", "direction_to_uv", "uv_to_direction",
    "BuildResult", "build", "BakePass", "BakeResult", "bake",
]

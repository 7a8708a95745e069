# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# The package's public names; their stubs are in _lumx.pyi.
from ._lumx import (
    BuildResult as BuildResult,
    Bundle as Bundle,
    Error as Error,
    Finding as Finding,
    LampSet as LampSet,
    Level as Level,
    LumxWarning as LumxWarning,
    Photometry as Photometry,
    RadianceVolume as RadianceVolume,
    RayFile as RayFile,
    RaysetInfo as RaysetInfo,
    Spread as Spread,
    Summary as Summary,
    __version__ as __version__,
    abi_namespace as abi_namespace,
    BakePass as BakePass,
    BakeResult as BakeResult,
    bake as bake,
    build as build,
    check as check,
    direction_to_uv as direction_to_uv,
    open_rays as open_rays,
    ray_dtype as ray_dtype,
    read_photometry as read_photometry,
    uv_to_direction as uv_to_direction,
    write_tm25 as write_tm25,
)

__all__: list[str]

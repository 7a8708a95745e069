#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Writes the libFuzzer dictionaries in tests/fuzz/dict/ (one per target, passed with -dict= by
# scripts/fuzz.sh): the keywords, element names and keys each reader looks for, and the numbers that
# stress its checks. Run it again after a reader learns a new keyword: python3 tests/fuzz/make_dicts.py
import pathlib

HERE = pathlib.Path(__file__).resolve().parent / "dict"

HOSTILE_NUMBERS = ["0", "-1", "1", "2", "90", "180", "270", "360", "2147483647", "-2147483648",
                   "4294967296", "9007199254740993", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf",
                   "0x10", "1,000", "12,5", "1.", ".5", "-0"]


def words(*groups):
    out = []
    for g in groups:
        out += g.split() if isinstance(g, str) else g
    return out


IES = words("IESNA:LM-63-1986 IESNA:LM-63-1991 IESNA91 IESNA:LM-63-1995 IESNA:LM-63-2002 IES:LM-63-2019",
            "[TEST] [TESTLAB] [TESTDATE] [NEARFIELD] [MANUFAC] [LUMCAT] [LUMINAIRE] [LAMPCAT] [LAMP] "
            "[BALLAST] [BALLASTCAT] [MAINTCAT] [DISTRIBUTION] [FLASHAREA] [COLORCONSTANT] [LAMPPOSITION] "
            "[ISSUEDATE] [OTHER] [SEARCH] [MORE] [FILEGENINFO] [_USER]",
            "TILT=NONE TILT=INCLUDE TILT= TILT=../x.tlt")
TM33 = words("IESTM33-22 IESTM33 TM-33 Version Header Manufacturer CatalogNumber Description GTIN Laboratory "
             "ReportNumber ReportDate DocumentCreator DocumentCreationDate UniqueIdentifier Comment MoreInfoURI "
             "Luminaire Dimensions Length Width Height Shape LuminousOpening EmissionAreas NumEmitter Emitter "
             "Quantity InputWattage InputWatts RatedLumens ColorTemperature FixedCCT ColorRendering CRI Ra Duv "
             "Equipment Goniometer Gonioradiometer Type LuminousData LuminousIntensity IntData NumberHorz "
             "NumberVert NumberMeasured Symm Symm_Full Symm_Bi_0 Symm_Bi_90 Symm_Quad Symm_None Symm_Arbitrary "
             "Multiplier Absolute AbsolutePhotometry Tilt TiltAngles NumberAngles TiltLampGeometry TiltSource "
             "BallastFactor SecondFactor PowerFactor CustomData Name Units CIE_C CIE_B CIE_A true false")
GLDF = words("Root Header Manufacturer FormatVersion GeneralDefinitions Files File Photometries Photometry "
             "PhotometryFileReference Emitters Emitter FixedLightEmitter PhotometryReference Geometries "
             "ModelGeometry SimpleGeometry GeometryFileReference ModelGeometryReference SimpleGeometryReference "
             "ProductDefinitions ProductMetaData ProductNumber Name Locale Variants Variant Geometry "
             "EmitterReference")
GLTF = words("asset version minVersion generator scene scenes nodes children mesh meshes matrix translation "
             "rotation scale primitives attributes POSITION NORMAL TEXCOORD_0 indices material mode "
             "materials pbrMetallicRoughness baseColorFactor metallicFactor roughnessFactor emissiveFactor "
             "alphaMode OPAQUE BLEND MASK doubleSided accessors bufferView byteOffset componentType count "
             "normalized type min max sparse SCALAR VEC2 VEC3 VEC4 MAT2 MAT3 MAT4 bufferViews buffer "
             "byteLength byteStride target buffers uri mimeType extensions extensionsUsed extensionsRequired "
             "extras name KHR_draco_mesh_compression KHR_mesh_quantization KHR_lights_punctual "
             "KHR_materials_emissive_strength emissiveStrength KHR_materials_transmission transmissionFactor "
             "KHR_materials_volume thicknessFactor attenuationColor attenuationDistance KHR_materials_ior ior "
             "KHR_materials_specular specularFactor specularColorFactor KHR_materials_diffuse_transmission "
             "diffuseTransmissionFactor diffuseTransmissionColorFactor KHR_texture_transform EXT_lights_ies "
             "LUMX_lights_rayset lights light point spot directional intensity color range innerConeAngle "
             "outerConeAngle multiplier")
BUNDLE = words("format lumx-bundle format_version generator bounding_sphere center radius channels Y R G B "
               "levels apl_count flux map_resolution maps bytes file pixel_type half float resolution sha256 "
               "parent position bounds min max error_vs_distance relative_distance relative_rmse provenance "
               "units intensity cd m radiance_unit irradiance volume sh_bands voxel_size counts window none "
               "hann lanczos vallee_poussin attachments media_type length levels/ ../ missing negative "
               "masks caps axis e1 e2 hull mask")
EXR = ["channels", "chlist", "compression", "dataWindow", "displayWindow", "box2i", "lineOrder",
       "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "v2f", "float", "tiles", "tiledesc",
       "type", "scanlineimage", "tiledimage", "chunkCount"]
RAYS = words("LTRF LTRFEND lt_rdf_version lt_datatype lt_data_origin lt_far_field_data lt_length_units "
             "lt_luminous_flux lt_photometric_flux lt_radiant_flux lt_color_info lt_startofdata lt_endofdata "
             "lm W mm cm m in ft um nm system none photometric",
             ["x y z dx dy dz flux", "x y z dx dy dz flux wavelength_nm", "x y z l m n flux",
              "x y z kx ky kz flux wavelength", "TM25", "ray format type", "number of rays"])


def quote(s):
    out = []
    for ch in s.encode("latin-1"):
        if ch in (0x22, 0x5C):
            out.append("\\" + chr(ch))
        elif 0x20 <= ch < 0x7F:
            out.append(chr(ch))
        else:
            out.append("\\x%02X" % ch)
    return '"' + "".join(out) + '"'


def write(name, comment, entries):
    seen, lines = set(), ["# " + comment, "# Written by tests/fuzz/make_dicts.py."]
    for e in entries:
        if e not in seen:
            seen.add(e)
            lines.append(quote(e))
    (HERE / (name + ".dict")).write_text("\n".join(lines) + "\n")


HERE.mkdir(exist_ok=True)
write("photometry", "IES LM-63 keywords and TILT forms, EULUMDAT separators, TM-33 XML and JSON names.",
      IES + ["\r\n", "\r", "\t", ",", " ", "\xef\xbb\xbf"] + HOSTILE_NUMBERS
      + ["<" + w + ">" for w in TM33] + ["</" + w + ">" for w in TM33] + ['"' + w + '":' for w in TM33]
      + ['<?xml version="1.0"?>', "<!DOCTYPE", "<![CDATA[", "&amp;", "&#0;", ' h="', ' v="', "[", "]", "{", "}"])
write("rayset", "LightTools, Zemax and plain-text ray keywords, TM-25 magic and numbers.",
      RAYS + HOSTILE_NUMBERS + ["\x00\x00\x00\x00", "\xff\xff\xff\x7f", "\xdd\x07\x00\x00", "\n", "#", "\t"])
write("gltf", "glTF 2.0 JSON keys and values, GLB chunk tags.",
      ['"' + w + '":' for w in GLTF] + ['"' + w + '"' for w in GLTF] + HOSTILE_NUMBERS
      + ["glTF", "JSON", "BIN\x00", "\x02\x00\x00\x00", "data:application/octet-stream;base64,", "DRACO",
         "5126", "5125", "5123", "5121", "5120", "5122", "34962", "34963", "[", "]", "{", "}", "null"])
write("bundle", "bundle manifest keys and values, OpenEXR magic and attribute names.",
      ['"' + w + '":' for w in BUNDLE] + ['"' + w + '"' for w in BUNDLE] + HOSTILE_NUMBERS
      + ["v/1\x01", "\x02\x00\x00\x00"] + EXR + ["[", "]", "{", "}", "null", "1e400", '"\\ud800"'])
write("gldf", "ZIP signatures and GLDF product.xml names.",
      ["PK\x03\x04", "PK\x01\x02", "PK\x05\x06", "PK\x06\x06", "PK\x06\x07", "product.xml", "ldc/", "geo/",
       "../", "/", "\\", "C:", "\x08\x00", "\x00\x00"]
      + ["<" + w + ">" for w in GLDF] + ["</" + w + ">" for w in GLDF]
      + ['contentType="ldc/eulumdat"', 'contentType="ldc/ies"', 'contentType="ldc/iesxml"',
         'contentType="geo/l3d"', 'type="localFileName"', 'type="url"', 'id="', 'fileId="', 'photometryId="',
         'emitterId="', 'geometryId="'])

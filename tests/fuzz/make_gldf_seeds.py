#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Writes the GLDF fuzz seeds in tests/data/fuzz/gldf/: small containers made from the project's own
# photometry files (never from ../shared/data), deflated and stored, with each photometry format, a
# geometry reference, a URL file and a reference to a file that is missing. Fixed timestamps keep the
# bytes reproducible: python3 tests/fuzz/make_gldf_seeds.py
import pathlib
import zipfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "data" / "fuzz" / "gldf"

PRODUCT = """<?xml version="1.0" encoding="UTF-8"?>
<Root>
  <Header>
    <Manufacturer>lumx fuzz seeds</Manufacturer>
    <FormatVersion major="1" minor="0" pre-release="3" />
  </Header>
  <GeneralDefinitions>
    <Files>
{files}
    </Files>
    <Photometries>
      <Photometry id="p1"><PhotometryFileReference fileId="f1" /></Photometry>
    </Photometries>
    <Emitters>
      <Emitter id="e1"><FixedLightEmitter><PhotometryReference photometryId="p1" /></FixedLightEmitter></Emitter>
    </Emitters>{geometries}
  </GeneralDefinitions>
  <ProductDefinitions>
    <ProductMetaData><ProductNumber><Locale language="en">F-1</Locale></ProductNumber>
      <Name><Locale language="en">Fuzz seed</Locale></Name></ProductMetaData>
    <Variants>
      <Variant id="v1"><Geometry>{variant_geometry}<EmitterReference emitterId="e1" /></Geometry></Variant>
    </Variants>
  </ProductDefinitions>
</Root>
"""


def product(content_type, name, extra_files="", geometries="", variant_geometry=""):
    files = '      <File id="f1" contentType="%s" type="localFileName">%s</File>' % (content_type, name)
    return PRODUCT.format(files=files + extra_files, geometries=geometries, variant_geometry=variant_geometry)


def write(name, entries, compression):
    with zipfile.ZipFile(OUT / name, "w", compression) as z:
        for entry, data in entries:
            info = zipfile.ZipInfo(entry, date_time=(2024, 1, 1, 0, 0, 0))
            info.compress_type = compression
            z.writestr(info, data)


OUT.mkdir(parents=True, exist_ok=True)
ldt = (ROOT / "tests/data/ldt/isym2_point.ldt").read_bytes()
ies = (ROOT / "samples/downlight.ies").read_bytes()
xml = (ROOT / "tests/data/tm33/floodlight_s001.xml").read_bytes()
write("eulumdat_deflated.gldf", [("product.xml", product("ldc/eulumdat", "a.ldt")), ("ldc/a.ldt", ldt)],
      zipfile.ZIP_DEFLATED)
write("ies_stored.gldf", [("product.xml", product("ldc/ies", "d.ies")), ("ldc/d.ies", ies)], zipfile.ZIP_STORED)
write("iesxml_deflated.gldf", [("product.xml", product("ldc/iesxml", "f.xml")), ("ldc/f.xml", xml)],
      zipfile.ZIP_DEFLATED)
geometry = """
    <Geometries>
      <ModelGeometry id="g1"><GeometryFileReference fileId="f2" /></ModelGeometry>
      <SimpleGeometry id="g2" />
    </Geometries>"""
extra = ('\n      <File id="f2" contentType="geo/l3d" type="localFileName">lamp.l3d</File>'
         '\n      <File id="f3" contentType="image/png" type="url">https://example.com/a.png</File>'
         '\n      <File id="f4" contentType="ldc/eulumdat" type="localFileName">missing.ldt</File>')
write("references_stored.gldf",
      [("product.xml", product("ldc/eulumdat", "a.ldt", extra, geometry, '<ModelGeometryReference geometryId="g1" />')),
       ("ldc/", b""), ("ldc/a.ldt", ldt), ("geo/lamp.l3d", b"PK\x03\x04 not a real l3d")], zipfile.ZIP_STORED)

#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Regenerates the bad-input corpus in this folder (tests/data/bad).

One small file per bad-input class of shared/docs/hard-cases.md section 6 (items 1-16), plus the valid
seed files the tests and a future fuzzer start from. tests/test_bad_input_ies.cpp and
tests/test_bad_input_ldt.cpp read these files and state the expected behaviour (E / W / X) of each.

Run from anywhere: python3 tests/data/bad/make_corpus.py
Files are written byte-exactly (line endings and encodings are part of what is tested).
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, data):
    if isinstance(data, str):
        data = data.encode("utf-8")
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


# ----------------------------------------------------------------------------------------------------
# IES LM-63
# ----------------------------------------------------------------------------------------------------

HEADER_2002 = (
    "IESNA:LM-63-2002\n"
    "[TEST] BAD-INPUT-BASE\n"
    "[TESTLAB] lumx tests\n"
    "[ISSUEDATE] 2024-01-01\n"
    "[MANUFAC] lumx\n"
)

# The base Type C table: V = 0 30 60 90, H = 0 90 180 270 360 (no symmetry), whole-number candela.
BASE_V = "0 30 60 90"
BASE_H = "0 90 180 270 360"
BASE_CD = [
    "500 400 200 0",
    "500 350 150 0",
    "500 300 100 0",
    "500 350 150 0",
    "500 400 200 0",
]


def ies(numbers_line1="1 1000 1 4 5 1 2 0.5 0.6 0", line2="1 1 25", v=BASE_V, h=BASE_H, cd=None,
        header=HEADER_2002, tilt="TILT=NONE\n", nl="\n", final_newline=True):
    cd = BASE_CD if cd is None else cd
    lines = [numbers_line1, line2, v, h] + list(cd)
    body = header.replace("\n", nl) + tilt.replace("\n", nl) + nl.join(lines)
    return body + (nl if final_newline else "")


# Valid seeds.
write("ies_valid_2002_typec.ies", ies())
write("ies_complete_no_final_newline.ies", ies(final_newline=False))

# Item 1: counts of -1, 0, 2^31-1, and counts the file cannot fill.
write("ies_count_vertical_negative.ies", ies(numbers_line1="1 1000 1 -1 5 1 2 0.5 0.6 0"))
write("ies_count_vertical_zero.ies", ies(numbers_line1="1 1000 1 0 5 1 2 0.5 0.6 0"))
write("ies_count_horizontal_negative.ies", ies(numbers_line1="1 1000 1 4 -1 1 2 0.5 0.6 0"))
write("ies_count_horizontal_zero.ies", ies(numbers_line1="1 1000 1 4 0 1 2 0.5 0.6 0"))
write("ies_count_huge.ies", ies(numbers_line1="1 1000 1 2147483647 5 1 2 0.5 0.6 0"))
write("ies_count_horizontal_huge.ies", ies(numbers_line1="1 1000 1 4 2147483647 1 2 0.5 0.6 0"))
# Both counts within ReadLimits::max_angles (3601) but 3000 x 3000 values cannot be in a 400-byte file.
write("ies_count_exceeds_data.ies", ies(numbers_line1="1 1000 1 3000 3000 1 2 0.5 0.6 0"))

# Item 2: truncated candela block (with and without a final newline).
trunc = ies(cd=BASE_CD[:3] + ["500 350"])
write("ies_truncated_candela.ies", trunc)
write("ies_truncated_candela_no_newline.ies", trunc.rstrip("\n"))

# Item 3: decreasing or repeated angles.
write("ies_vertical_decreasing.ies", ies(v="0 60 30 90"))
write("ies_vertical_repeated.ies", ies(v="0 30 30 90"))
write("ies_horizontal_decreasing.ies", ies(h="0 180 90 270 360"))
write("ies_horizontal_repeated.ies", ies(h="0 90 90 270 360"))

# Item 4: nan / inf anywhere, negative candela.
write("ies_candela_nan.ies", ies(cd=BASE_CD[:2] + ["500 nan 100 0"] + BASE_CD[3:]))
write("ies_candela_inf.ies", ies(cd=BASE_CD[:2] + ["500 inf 100 0"] + BASE_CD[3:]))
write("ies_angle_nan.ies", ies(v="0 30 nan 90"))
write("ies_multiplier_inf.ies", ies(numbers_line1="1 1000 inf 4 5 1 2 0.5 0.6 0"))
# -0.25 with a peak of 500: |value| <= 1e-3 x peak, measurement noise -> W.
write("ies_candela_negative_noise.ies", ies(cd=BASE_CD[:2] + ["500 300 100 -0.25"] + BASE_CD[3:]))
# -50 with a peak of 500 -> E.
write("ies_candela_negative_large.ies", ies(cd=BASE_CD[:2] + ["500 300 100 -50"] + BASE_CD[3:]))

# A product that overflows: value x multiplier = inf must be refused like a literal inf.
write("ies_multiplier_overflow.ies", ies(numbers_line1="1 1000 1e308 4 5 1 2 0.5 0.6 0"))
write("ies_candela_overflow.ies", ies(numbers_line1="1 1000 10 4 5 1 2 0.5 0.6 0",
                                      cd=BASE_CD[:2] + ["500 300 1e308 0"] + BASE_CD[3:]))

# Item 5: absolute photometry (lumens = -1), analytic flux.
iso_v = "0 10 30 45 60 90 120 150 170 180"  # deliberately non-uniform
write("ies_lumens_absolute_isotropic.ies",
      ies(numbers_line1="1 -1 1 10 1 1 2 0 0 0", v=iso_v, h="0", cd=["100 " * 9 + "100"]))
cos_v = [5 * i for i in range(19)]  # 0..90 step 5
I0 = 1000.0
cos_cd = [I0 * math.cos(math.radians(g)) for g in cos_v]
cos_cd[-1] = 0.0  # cos(90 deg) is exactly 0
write("ies_lumens_absolute_cosine.ies",
      ies(numbers_line1="1 -1 1 19 1 1 2 0 0 0", v=" ".join(str(g) for g in cos_v), h="0",
          cd=[" ".join("%.17g" % c for c in cos_cd)]))

# Item 6: Type C horizontal ranges and the symmetry they imply. V = 0 45 90 135 180.
SV = "0 45 90 135 180"
write("ies_sym_rotational.ies", ies(numbers_line1="1 1000 1 5 1 1 2 0 0 0", v=SV, h="0",
                                    cd=["300 200 100 50 10"]))
write("ies_sym_quadrant.ies", ies(numbers_line1="1 1000 2 5 3 1 2 0 0 0", v=SV, h="0 45 90",
                                  cd=["300 200 100 50 10", "300 180 90 40 10", "300 160 80 30 10"]))
write("ies_sym_c0_c180.ies", ies(numbers_line1="1 1000 1 5 3 1 2 0 0 0", v=SV, h="0 90 180",
                                 cd=["300 200 100 50 10", "300 180 90 40 10", "300 160 80 30 10"]))
write("ies_sym_c90_c270.ies", ies(header="IESNA:LM-63-1995\n[TEST] C90-C270\n",
                                  numbers_line1="1 1000 1 5 3 1 2 0 0 0", v=SV, h="90 180 270",
                                  cd=["300 200 100 50 10", "300 180 90 40 10", "300 160 80 30 10"]))
write("ies_sym_range_0_270.ies", ies(numbers_line1="1 1000 1 5 4 1 2 0 0 0", v=SV, h="0 90 180 270",
                                     cd=["300 200 100 50 10"] * 4))
write("ies_sym_range_0_45.ies", ies(numbers_line1="1 1000 1 5 2 1 2 0 0 0", v=SV, h="0 45",
                                    cd=["300 200 100 50 10"] * 2))

# Item 7: TILT.
write("ies_tilt_include_valid.ies", ies(tilt="TILT=INCLUDE\n1\n3\n0 45 90\n1 0.8 0.5\n"))
write("ies_tilt_include_zero_pairs.ies", ies(tilt="TILT=INCLUDE\n1\n0\n\n\n"))
# Pair count 3 but only 2 multipliers: the photometric numbers that follow are pulled into the tilt
# data, which misaligns every later field (units type becomes 0.5, lamp count -1, ...).
write("ies_tilt_include_too_few.ies",
      ies(tilt="TILT=INCLUDE\n1\n3\n0 45 90\n1 0.9\n", numbers_line1="1 -1 1 4 5 1 2 0.5 0.5 0"))
write("ies_tilt_include_huge_count.ies", ies(tilt="TILT=INCLUDE\n1\n2147483647\n0 45 90\n1 0.8 0.5\n"))
write("ies_tilt_include_negative_count.ies", ies(tilt="TILT=INCLUDE\n1\n-3\n0 45 90\n1 0.8 0.5\n"))
write("ies_tilt_file_missing.ies", ies(tilt="TILT=ies_tilt_does_not_exist.tlt\n"))
write("ies_tilt_file_traversal.ies", ies(tilt="TILT=../../x\n"))
write("ies_tilt_file_subdir.ies", ies(tilt="TILT=sub/x.tlt\n"))
write("ies_tilt_external_valid.ies", ies(tilt="TILT=ies_tilt_external_valid.tlt\n"))
write("ies_tilt_external_valid.tlt", "1\n3\n0 45 90\n1 0.8 0.5\n")

# Item 8: Types A and B, openings with negative (curved) dimensions.
TYPEB_V = "-90 -45 0 45 90"
TYPEB_CD = ["10 300 1000 300 10", "10 250 800 250 10", "10 100 400 100 10"]
write("ies_valid_typeb.ies", ies(header=HEADER_2002.replace("BAD-INPUT-BASE", "TYPE-B"),
                                 numbers_line1="1 -1 1 5 3 2 2 0 0 0", v=TYPEB_V, h="0 45 90",
                                 cd=TYPEB_CD))
write("ies_valid_typea.ies", ies(header=HEADER_2002.replace("BAD-INPUT-BASE", "TYPE-A"),
                                 numbers_line1="1 -1 1 5 3 3 2 0 0 0", v=TYPEB_V, h="0 45 90",
                                 cd=TYPEB_CD))
write("ies_opening_circle.ies", ies(numbers_line1="1 1000 1 4 5 1 2 -0.3 -0.3 0"))
write("ies_opening_circle_feet.ies", ies(numbers_line1="1 1000 1 4 5 1 1 -1 -1 0"))

# Item 9: delimiters and old headers. All hold the base table.
write("ies_delim_commas.ies", ies(numbers_line1="1,1000,1,4,5,1,2,0.5,0.6,0", line2="1, 1, 25",
                                  v="0,30,60,90", h="0, 90, 180, 270, 360",
                                  cd=[r.replace(" ", ",") for r in BASE_CD]))
write("ies_delim_tabs.ies", ies(numbers_line1="1\t1000\t1\t4\t5\t1\t2\t0.5\t0.6\t0", line2="\t1 \t1\t25",
                                v="0\t30\t60\t90", h="0\t90\t180\t270\t360",
                                cd=[r.replace(" ", "\t") for r in BASE_CD]))
write("ies_crlf.ies", ies(nl="\r\n"))
write("ies_lone_cr.ies", ies(nl="\r"))
write("ies_bom.ies", b"\xef\xbb\xbf" + ies().encode())
write("ies_latin1_keywords.ies",
      ies(header="IESNA:LM-63-2002\n[TEST] BAD-INPUT-BASE\n[TESTLAB] lumx tests\n[ISSUEDATE] 2024-01-01\n"
                 "[MANUFAC] lumx\n[LUMINAIRE] BEAM 120\xb0 \xe9clairage\n").encode("latin-1"))
write("ies_1986_no_version.ies",
      ies(header="REPORT NUMBER: 1234\nLUMINAIRE: TEST DOWNLIGHT\nLAMP: 1 X 1000 LM\n"))
write("ies_long_label.ies",
      ies(header="IESNA:LM-63-1995\n[TEST] " + "X" * 120 + "\n[MANUFAC] lumx\n"))
# Real-world header quirks (formats.md 1.6): keyword text containing "TILT=", a version line with a
# blank, and a 2019 file whose file-generation type 1.10000 must not scale the candela (ballast 0.9 is
# reported, not applied either).
write("ies_keyword_mentions_tilt.ies",
      ies(header=HEADER_2002 + "[OTHER] see TILT=INCLUDE note\n[LAMP] LED TILT=30\n"))
write("ies_version_with_space.ies", ies(header=HEADER_2002.replace("IESNA:LM", "IESNA: LM")))
write("ies_2019_filegen_type.ies", ies(header=HEADER_2002.replace("IESNA:LM-63-2002", "IES:LM-63-2019"),
                                       line2="0.9 1.10000 25"))
# Numbers wrapped at arbitrary points, leading blanks, ".5", one number per line, trailing blank lines.
write("ies_wrapped_values.ies",
      HEADER_2002 + "TILT=NONE\n1\n1000 1\n4 5 1 2 .5\n0.6 0 1\n1 25 0 30\n 60 90 0\n90\n180 270 360 500 400\n"
      "200 0 500 350 150 0 500 300 100 0 500\n 350 150\n0\n500 400\n200\n0\n\n\n")

# ----------------------------------------------------------------------------------------------------
# EULUMDAT
# ----------------------------------------------------------------------------------------------------


def ldt(isym=4, mc=8, dc=45, ng=5, dg=45, c_angles=None, g_angles=None, intensities=None, lamps=None,
        ityp=None, lor="80", extra=None, nl="\r\n", n_lamp_sets=None, fields=None):
    """EULUMDAT text: 26 header lines, 6 lines per lamp set, 10 direct ratios, Mc C angles,
    Ng gamma angles, intensities (one value per line). `fields` overrides a header line by number."""
    ityp = (1 if isym == 1 else 3) if ityp is None else ityp  # Ityp consistent with Isym
    lamps = [("1", "LED", "1000", "3000K", "80", "10")] if lamps is None else lamps
    if c_angles is None:
        c_angles = ["%g" % (i * 360.0 / mc) for i in range(mc)]
    g_angles = [str(i * dg) for i in range(ng)] if g_angles is None else g_angles
    head = {
        1: "lumx test corpus", 2: str(ityp), 3: str(isym), 4: str(mc), 5: str(dc), 6: str(ng), 7: str(dg),
        8: "R-1", 9: "Test luminaire", 10: "T-1", 11: "test.ldt", 12: "2024-01-01 lumx",
        13: "100", 14: "100", 15: "50", 16: "80", 17: "80", 18: "0", 19: "0", 20: "0", 21: "0",
        22: "100", 23: lor, 24: "1", 25: "0",
        26: str(len(lamps)) if n_lamp_sets is None else n_lamp_sets,
    }
    if fields:
        head.update(fields)
    out = [head[i] for i in range(1, 27)]
    for lamp in lamps:
        out += list(lamp)
    out += ["0.5", "0.6", "0.65", "0.7", "0.75", "0.8", "0.85", "0.88", "0.92", "0.95"]
    out += c_angles + g_angles + intensities
    if extra:
        out += extra
    return nl.join(out) + nl


# Isym 4, Mc 8 (C0..C315 by 45), Ng 5 (gamma 0..180 by 45): stored planes C0, C45, C90.
ISYM4_CD = ["300", "200", "100", "50", "10",
            "300", "180", "90", "40", "10",
            "300", "160", "80", "30", "10"]
write("ldt_valid_isym4.ldt", ldt(intensities=ISYM4_CD))
# Item 16: one valid file per Isym, all C0..C315 by 45 and gamma 0..180 by 45.
write("ldt_isym1_expand.ldt", ldt(isym=1, intensities=["300", "200", "100", "50", "10"]))
# Isym 2 stores C0..C180 (5 planes); lamp flux 2000 lm, so cd = 2 x the file's cd/klm.
write("ldt_isym2_expand.ldt", ldt(isym=2, lamps=[("1", "LED", "2000", "3000K", "80", "20")],
                                  intensities=["300", "200", "100", "50", "10",
                                               "300", "190", "95", "45", "10",
                                               "300", "180", "90", "40", "10",
                                               "300", "170", "85", "35", "10",
                                               "300", "160", "80", "30", "10"]))
# Isym 3 stores C270, C315, C0, C45, C90 (3Mc/4+1 .. 3Mc/4+1+Mc/2, wrapping).
write("ldt_isym3_expand.ldt", ldt(isym=3, intensities=["300", "150", "75", "25", "10",    # C270
                                                       "300", "155", "77", "27", "10",    # C315
                                                       "300", "160", "80", "30", "10",    # C0
                                                       "300", "170", "85", "35", "10",    # C45
                                                       "300", "180", "90", "40", "10"]))  # C90
write("ldt_isym4_expand.ldt", ldt(isym=4, intensities=ISYM4_CD))
ISYM0_CD = []
for k in range(8):
    ISYM0_CD += ["300", str(200 - 5 * k), str(100 - 3 * k), str(50 - 2 * k), "10"]
write("ldt_isym0_expand.ldt", ldt(isym=0, intensities=ISYM0_CD))

# Item 11: Mc not a multiple of what Isym needs.
write("ldt_isym2_mc_odd.ldt", ldt(isym=2, mc=7, dc=0, c_angles=["0", "50", "100", "150", "200", "250", "300"],
                                  intensities=ISYM4_CD + ["300", "150", "75", "25", "10"]))
write("ldt_isym3_mc_odd.ldt", ldt(isym=3, mc=7, dc=0, c_angles=["0", "50", "100", "150", "200", "250", "300"],
                                  intensities=ISYM4_CD + ["300", "150", "75", "25", "10"]))
# Mc = 6 is even, but Isym 3 stores C270..C90 and Mc = 6 has neither a C90 nor a C270 plane.
write("ldt_isym3_mc_not_multiple_of_4.ldt", ldt(isym=3, mc=6, dc=60, intensities=ISYM4_CD + ["300", "150", "75", "25", "10"]))
write("ldt_isym4_mc_not_multiple.ldt", ldt(isym=4, mc=6, dc=60, intensities=ISYM4_CD))

# Item 12: Nc > 721, Ng > 361, spacing <= 0, lamp sets > 20 or <= 0.
mc = 722
write("ldt_nc_too_many.ldt", ldt(isym=0, mc=mc, dc=0, ng=2, dg=90, g_angles=["0", "90"],
                                 c_angles=["%.6f" % (i * 360.0 / mc) for i in range(mc)],
                                 intensities=["100", "50"] * mc))
ng = 362
write("ldt_ng_too_many.ldt", ldt(isym=1, mc=1, dc=0, ng=ng, dg=0, c_angles=["0"],
                                 g_angles=["%.6f" % (i * 180.0 / (ng - 1)) for i in range(ng)],
                                 intensities=["100"] * ng))
write("ldt_mc_huge.ldt", ldt(isym=4, mc=2147483647, dc=45, c_angles=[str(45 * i) for i in range(8)],
                             intensities=ISYM4_CD))
write("ldt_mc_negative.ldt", ldt(isym=4, mc=-1, dc=45, c_angles=[str(45 * i) for i in range(8)],
                                 intensities=ISYM4_CD))
write("ldt_dc_negative.ldt", ldt(dc=-45, intensities=ISYM4_CD))
write("ldt_gamma_spacing_zero.ldt", ldt(g_angles=["0", "45", "45", "135", "180"], dg=0, intensities=ISYM4_CD))
write("ldt_c_spacing_negative.ldt",
      ldt(isym=0, dc=0, c_angles=["0", "45", "90", "135", "180", "225", "315", "270"],
          intensities=ISYM0_CD))
# Dc = Dg = 0 (non-equidistant) with non-uniform angles is a real-world layout that must load.
write("ldt_nonuniform_dc0.ldt", ldt(dg=0, g_angles=["0", "30", "90", "135", "180"], intensities=ISYM4_CD))
LAMP = ("1", "LED", "50", "3000K", "80", "1")
write("ldt_lamp_sets_21.ldt", ldt(lamps=[LAMP] * 21, intensities=ISYM4_CD))
write("ldt_lamp_sets_zero.ldt", ldt(lamps=[], intensities=ISYM4_CD))
write("ldt_lamp_sets_negative.ldt", ldt(lamps=[], n_lamp_sets="-1", intensities=ISYM4_CD))

# Item 13: decimal comma.
write("ldt_decimal_comma.ldt", ldt(lor="75,5", intensities=["10,25" if v == "10" else v for v in ISYM4_CD]))
write("ldt_thousands_comma.ldt", ldt(lamps=[("1", "LED", "1,000", "3000K", "80", "10")], intensities=ISYM4_CD))

# Item 14: integer fields holding a fraction, an exponent, nan.
write("ldt_int_field_fraction.ldt", ldt(fields={6: "3.7"}, intensities=ISYM4_CD))
write("ldt_int_field_exponent.ldt", ldt(fields={4: "1e10"}, intensities=ISYM4_CD))
write("ldt_int_field_nan.ldt", ldt(fields={3: "nan"}, intensities=ISYM4_CD))
write("ldt_lamp_count_fraction.ldt", ldt(lamps=[("1.5", "LED", "1000", "3000K", "80", "10")],
                                         intensities=ISYM4_CD))
write("ldt_intensity_nan.ldt", ldt(intensities=ISYM4_CD[:6] + ["nan"] + ISYM4_CD[7:]))
write("ldt_intensity_inf.ldt", ldt(intensities=ISYM4_CD[:6] + ["inf"] + ISYM4_CD[7:]))

# Negative intensities: noise (|v| <= 1e-3 x peak 300) -> W, beyond -> E; cd/klm x flux overflowing -> E.
write("ldt_intensity_negative_noise.ldt", ldt(intensities=ISYM4_CD[:14] + ["-0.25"]))
write("ldt_intensity_negative_large.ldt", ldt(intensities=ISYM4_CD[:6] + ["-160"] + ISYM4_CD[7:]))
write("ldt_intensity_overflow.ldt", ldt(lamps=[("1", "LED", "10000", "3000K", "80", "10")],
                                        intensities=ISYM4_CD[:6] + ["1e308"] + ISYM4_CD[7:]))
# Line endings other than the spec's CR LF, and a BOM.
write("ldt_lf_only.ldt", ldt(intensities=ISYM4_CD, nl="\n"))
write("ldt_bom.ldt", b"\xef\xbb\xbf" + ldt(intensities=ISYM4_CD).encode())

# Item 15: negative lamp count = absolute photometry.
write("ldt_absolute_negative_lamps.ldt", ldt(lamps=[("-1", "LED", "1500", "3000K", "80", "12")],
                                             intensities=ISYM4_CD))

# Truncation (any LDT): intensities stop early.
write("ldt_truncated.ldt", ldt(intensities=ISYM4_CD[:11]))

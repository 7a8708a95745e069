// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES TM-33 / ATLA S001: the three root forms and the JSON form read from files written by hand from the
// documents (tests/data/tm33), TM-33 -> model -> TM-33 exact, kept blocks written back, TM-33 <-> IES <->
// EULUMDAT on every real IES and LDT file, and located errors for bad input.
#include <lumx/io/photometry_io.h>
#include <lumx/io/tm33_io.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/resample.h>

#include <gtest/gtest.h>

#include "bad_input_support.h"
#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

using namespace lumx;
namespace fs = std::filesystem;

namespace {

fs::path fixture(const std::string& name) { return lumx_test::data_dir() / "tm33" / name; }

Photometry read_fixture(const std::string& name) { return read_photometry(fixture(name).string()); }

bool same_elements(const DataElement& a, const DataElement& b) {
  if (a.name != b.name || a.attributes != b.attributes || a.text != b.text || a.children.size() != b.children.size())
    return false;
  for (std::size_t i = 0; i < a.children.size(); ++i)
    if (!same_elements(a.children[i], b.children[i])) return false;
  return true;
}

std::vector<std::pair<std::string, std::string>> nonempty_keywords(const Photometry& p) {
  std::vector<std::pair<std::string, std::string>> k;
  for (const auto& kw : p.keywords)
    if (!kw.value.empty()) k.emplace_back(kw.name, kw.value);
  std::sort(k.begin(), k.end());
  return k;
}

/// Everything the model holds, compared exactly (TM-33 numbers are written as the shortest text that reads
/// back to the same double), except the source description and line numbers.
void expect_same_model(const Photometry& a, const Photometry& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.type, b.type);
  EXPECT_EQ(a.symmetry, b.symmetry);
  EXPECT_EQ(a.horizontal_deg, b.horizontal_deg);
  EXPECT_EQ(a.vertical_deg, b.vertical_deg);
  EXPECT_EQ(a.candela, b.candela);
  EXPECT_EQ(a.absolute, b.absolute);
  ASSERT_EQ(a.lamp_sets.size(), b.lamp_sets.size());
  for (std::size_t i = 0; i < a.lamp_sets.size(); ++i) {
    const LampSet &x = a.lamp_sets[i], &y = b.lamp_sets[i];
    EXPECT_EQ(std::abs(x.count), std::abs(y.count)) << i;
    EXPECT_EQ(x.type, y.type) << i;
    // Rated flux travels as flux per lamp (RatedLumens) times Quantity: one rounding each way.
    EXPECT_NEAR(x.flux_lm, y.flux_lm, 4e-16 * std::abs(x.flux_lm)) << i;
    EXPECT_EQ(x.watts, y.watts) << i;
    EXPECT_EQ(x.color, y.color) << i;
    EXPECT_EQ(x.cri, y.cri) << i;
  }
  EXPECT_EQ(a.ballast_factor, b.ballast_factor);
  EXPECT_EQ(a.ies_second_factor, b.ies_second_factor);
  EXPECT_EQ(a.input_watts, b.input_watts);
  EXPECT_EQ(a.units, b.units);
  EXPECT_EQ(a.opening.width_m, b.opening.width_m);
  EXPECT_EQ(a.opening.length_m, b.opening.length_m);
  EXPECT_EQ(a.opening.height_m, b.opening.height_m);
  EXPECT_EQ(nonempty_keywords(a), nonempty_keywords(b));
  ASSERT_EQ(a.tilt.has_value(), b.tilt.has_value());
  if (a.tilt) {
    EXPECT_EQ(a.tilt->angles_deg, b.tilt->angles_deg);
    EXPECT_EQ(a.tilt->multipliers, b.tilt->multipliers);
    EXPECT_EQ(a.tilt->lamp_geometry, b.tilt->lamp_geometry);
  }
  EXPECT_EQ(a.ldt.company, b.ldt.company);
  EXPECT_EQ(a.ldt.ityp, b.ldt.ityp);
  EXPECT_EQ(a.ldt.luminaire_length_mm, b.ldt.luminaire_length_mm);
  EXPECT_EQ(a.ldt.area_height_mm[2], b.ldt.area_height_mm[2]);
  EXPECT_EQ(a.ldt.dff_percent, b.ldt.dff_percent);
  EXPECT_EQ(a.ldt.direct_ratios, b.ldt.direct_ratios);
  EXPECT_EQ(a.ldt.date_user, b.ldt.date_user);
}

/// The candela of `b` at every stored angle of `a` within `rel` of `a`'s peak, and the flux within 0.1 %.
double flux_and_candela(const Photometry& a, const Photometry& b, double rel, const std::string& what) {
  const IntensityTable ta(a), tb(b);
  EXPECT_LE(lumx_test::max_candela_difference(a, b), rel * ta.max_cd()) << what;
  const double df = std::abs(tb.flux_lm() - ta.flux_lm()) / ta.flux_lm();
  EXPECT_LE(df, 1e-3) << what;  // the 0.1 % requirement
  return df;
}

}  // namespace

TEST(Tm33, ReadsTheTm33_18FormWrittenByHand) {
  const Photometry p = read_fixture("troffer_tm33_18.xml");
  EXPECT_EQ(p.source.format, "TM-33");
  EXPECT_EQ(p.source.version, "TM-33-18");
  EXPECT_EQ(p.tm33.root, "IESTM33");
  EXPECT_EQ(p.type, PhotometricType::C);
  EXPECT_EQ(p.symmetry, Symmetry::quadrant);  // implied by the horizontal range 0..90, as in LM-63
  EXPECT_EQ(p.horizontal_deg, (std::vector<double>{0, 45, 90}));
  ASSERT_EQ(p.vertical_deg.size(), 7u);
  EXPECT_EQ(p.at(1, 2), 830);  // h 45, v 30
  EXPECT_EQ(p.at(2, 5), 120);  // h 90, v 75
  EXPECT_FALSE(p.absolute);
  ASSERT_EQ(p.lamp_sets.size(), 1u);
  EXPECT_EQ(p.lamp_sets[0].count, 2);
  EXPECT_EQ(p.lamp_sets[0].flux_lm, 5200);  // RatedLumens is per lamp: 2 x 2600 lm
  EXPECT_EQ(p.lamp_sets[0].watts, 62);
  EXPECT_EQ(p.lamp_sets[0].color, "4000");
  EXPECT_EQ(p.lamp_sets[0].cri, "85");
  EXPECT_EQ(p.ballast_factor, 0.95);
  ASSERT_TRUE(p.tilt);
  EXPECT_EQ(p.tilt->multipliers, (std::vector<double>{1, 0.95, 0.9}));
  EXPECT_EQ(p.opening.length_m, 1.2);
  EXPECT_EQ(p.opening.width_m, 0.3);
  EXPECT_EQ(p.ldt.luminaire_length_mm, 1250);
  EXPECT_EQ(p.tm33.goniometer_type, "IES_C");
  EXPECT_EQ(p.tm33.luminous_flux_lm, 3950);
  ASSERT_TRUE(p.find_keyword("MANUFAC"));
  EXPECT_EQ(p.find_keyword("MANUFAC")->value, "lumx test luminaires");
  EXPECT_EQ(p.find_keyword("TEST")->value, "LUMX-TM33-18-001");
  EXPECT_EQ(p.find_keyword("ISSUEDATE")->value, "2024-03-01");
  std::size_t comments = 0;
  for (const auto& k : p.keywords) comments += k.name == "OTHER";
  EXPECT_EQ(comments, 2u);
  // Kept as data: header extras, equipment, the emitter's colour, channel and area blocks, vendor data.
  std::vector<std::string> kept;
  for (const auto& k : p.tm33.kept) kept.push_back(k.parent + ":" + k.element.name);
  for (const char* want : {"Header:DocumentCreator", "Header:UniqueIdentifier", ":Equipment", "Emitter[0]:ColorTemperature",
                           "Emitter[0]:ColorRendering", "Emitter[0]:Channels", "Emitter[0]:EmissionAreas", ":CustomData"})
    EXPECT_NE(std::find(kept.begin(), kept.end(), want), kept.end()) << want;
  // Lines of the IntData values locate validation findings.
  ASSERT_EQ(p.source.candela_lines.size(), p.candela.size());
  EXPECT_GT(p.source.candela_lines[0], 60u);
}

TEST(Tm33, ReadsTheTm33_23FormWithSymmAndMultiplier) {
  const Photometry p = read_fixture("downlight_tm33_23.xml");
  EXPECT_EQ(p.source.version, "TM-33-23");
  EXPECT_EQ(p.symmetry, Symmetry::rotational);
  EXPECT_TRUE(p.absolute);
  EXPECT_EQ(p.candela_multiplier, 2);
  ASSERT_EQ(p.candela.size(), 7u);
  EXPECT_EQ(p.candela[0], 500);  // 250 x Multiplier 2
  EXPECT_EQ(p.candela[3], 240);
  EXPECT_EQ(p.lamp_sets[0].flux_lm, 0);
  EXPECT_EQ(p.input_watts, 12.5);
  bool spectral = false;
  for (const auto& k : p.tm33.kept)
    if (k.parent == "Emitter[0]" && k.element.name == "SpectralData") spectral = k.element.children.at(0).children.size() == 7;
  EXPECT_TRUE(spectral);  // EmitterSpectral: NumberWavelength, Normalized and five PwrData
}

TEST(Tm33, ReadsTheS001RootAndTypeB) {
  const Photometry p = read_fixture("floodlight_s001.xml");
  EXPECT_EQ(p.tm33.root, "LuminaireOpticalData");
  EXPECT_EQ(p.tm33.version, "1.0");
  EXPECT_EQ(p.type, PhotometricType::B);
  EXPECT_EQ(p.symmetry, Symmetry::lateral);
  EXPECT_EQ(p.at(0, 2), 900);
  EXPECT_EQ(p.rated_lamp_flux_lm(), 4000);
}

TEST(Tm33, MirrorsC90C270DataStoredOnTheOtherHalf) {
  // Symm_Bi_90 stored as C270, C315, C0, C45, C90: the model stores C90..C270 (I(C) = I(180 - C)).
  const Photometry p = read_fixture("washer_bi90_tm33_23.xml");
  EXPECT_EQ(p.symmetry, Symmetry::plane_c90_c270);
  EXPECT_EQ(p.horizontal_deg, (std::vector<double>{90, 135, 180, 225, 270}));
  EXPECT_EQ(p.at(2, 0), 500);  // C180 <- C0
  EXPECT_EQ(p.at(1, 0), 480);  // C135 <- C45
  EXPECT_EQ(p.at(3, 1), 260);  // C225 <- C315
  const IntensityTable t(p);
  EXPECT_NEAR(t.at_angles(0, 45), 300, 1e-9);
  EXPECT_NEAR(t.at_angles(45, 45), 280, 1e-9);
  EXPECT_NEAR(t.at_angles(315, 45), 260, 1e-9);
}

TEST(Tm33, JsonFormReadsToTheSameModelAsXml) {
  const Photometry x = read_fixture("downlight_tm33_23.xml");
  const Photometry j = read_fixture("downlight_tm33_23.json");
  expect_same_model(x, j, "xml vs json");
  ASSERT_EQ(x.tm33.kept.size(), j.tm33.kept.size());
  for (std::size_t i = 0; i < x.tm33.kept.size(); ++i) {
    EXPECT_EQ(x.tm33.kept[i].parent, j.tm33.kept[i].parent);
    EXPECT_EQ(x.tm33.kept[i].element.name, j.tm33.kept[i].element.name);
  }
}

TEST(Tm33, WriteThenReadKeepsEverythingExactly) {
  for (const char* name : {"troffer_tm33_18.xml", "downlight_tm33_23.xml", "floodlight_s001.xml",
                           "washer_bi90_tm33_23.xml", "downlight_tm33_23.json"}) {
    const Photometry p = read_fixture(name);
    for (const Tm33Version v : {Tm33Version::tm33_23, Tm33Version::tm33_18}) {
      Tm33WriteOptions o;
      o.version = v;
      const std::string tag = std::string(name) + (v == Tm33Version::tm33_23 ? " as TM-33-23" : " as TM-33-18");
      const Photometry x = read_tm33_xml(format_tm33_xml(p, o), "back.xml");
      const Photometry j = read_tm33_json(format_tm33_json(p, o), "back.json");
      expect_same_model(p, x, tag + " XML");
      expect_same_model(p, j, tag + " JSON");
      EXPECT_EQ(x.tm33.luminous_flux_lm, p.tm33.luminous_flux_lm > 0 ? p.tm33.luminous_flux_lm : x.tm33.luminous_flux_lm);
      // Kept blocks come back, element for element (Equipment is rewritten with the photometric type).
      for (const Photometry* back : {&x, &j}) {
        ASSERT_EQ(back->tm33.kept.size(), p.tm33.kept.size()) << tag;
        for (std::size_t i = 0; i < p.tm33.kept.size(); ++i) {
          EXPECT_EQ(back->tm33.kept[i].parent, p.tm33.kept[i].parent) << tag;
          if (p.tm33.kept[i].element.name != "Equipment") {
            EXPECT_TRUE(same_elements(back->tm33.kept[i].element, p.tm33.kept[i].element))
                << tag << ": " << p.tm33.kept[i].element.name;
          }
        }
      }
    }
  }
}

TEST(Tm33, KeptSpectralDataIsWrittenBackInPlace) {
  const std::string xml = format_tm33_xml(read_fixture("downlight_tm33_23.xml"));
  const auto spectral = xml.find("<SpectralData>");
  const auto intensity = xml.find("<LuminousData>");
  const auto regulatory = xml.find("<Regulatory>");
  ASSERT_NE(spectral, std::string::npos);
  EXPECT_LT(intensity, spectral);  // the TM-33-23 element order
  EXPECT_LT(spectral, regulatory);
  EXPECT_NE(xml.find("<PwrData w=\"600\">1</PwrData>"), std::string::npos);
  EXPECT_NE(xml.find("<Multiplier>1</Multiplier>"), std::string::npos);  // candela written absolute
  EXPECT_NE(xml.find("<IntData h=\"0\" v=\"0\">500</IntData>"), std::string::npos);
  const std::string v18 = format_tm33_xml(read_fixture("downlight_tm33_23.xml"), Tm33WriteOptions{Tm33Version::tm33_18, 0});
  EXPECT_EQ(v18.find("<Symm>"), std::string::npos);
  EXPECT_NE(v18.find("<IESTM33>"), std::string::npos);
  EXPECT_NE(v18.find("<Version>1.0</Version>"), std::string::npos);
}

TEST(Tm33, HandWrittenFilesThroughIesAndLdtKeepFluxAndCandela) {
  for (const char* name : {"troffer_tm33_18.xml", "downlight_tm33_23.xml", "washer_bi90_tm33_23.xml"}) {
    const Photometry t = read_fixture(name);
    const Photometry i = read_ies(format_ies(t), "t.ies");
    const Photometry l = read_ldt(format_ldt(i), "t.ldt");
    const Photometry back = read_tm33_xml(format_tm33_xml(l), "t.xml");
    flux_and_candela(t, i, 1e-6, std::string(name) + " -> IES");
    flux_and_candela(t, l, 2e-6, std::string(name) + " -> IES -> LDT");
    flux_and_candela(t, back, 2e-6, std::string(name) + " -> IES -> LDT -> TM-33");
  }
}

TEST(Tm33, EveryRealIesAndLdtFileRoundTrips) {
  if (lumx_test::shared_dir().empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  std::size_t n = 0;
  double worst_ies = 0, worst_ldt = 0;
  for (const auto& f : lumx_test::shared_photometry_files({".ies", ".ldt"})) {
    if (f.filename() == "test_file_format_error.ies") continue;
    SCOPED_TRACE(f.string());
    const Photometry p = read_photometry(f.string());
    // Model -> TM-33 -> model is exact, in both syntaxes.
    const Photometry x = read_tm33_xml(format_tm33_xml(p), "x.xml");
    const Photometry j = read_tm33_json(format_tm33_json(p), "x.json");
    expect_same_model(p, x, "TM-33 XML");
    expect_same_model(p, j, "TM-33 JSON");
    // And back to the source format.
    if (p.source.format == "IES") {
      const Photometry back = read_ies(format_ies(x), "back.ies");
      worst_ies = std::max(worst_ies, flux_and_candela(p, back, 1e-6, "IES -> TM-33 -> IES"));
      if (p.type == PhotometricType::C) {
        const Photometry l = read_ldt(format_ldt(x), "x.ldt");
        const Photometry t2 = read_tm33_xml(format_tm33_xml(l), "t2.xml");
        worst_ldt = std::max(worst_ldt, flux_and_candela(p, t2, 2e-6, "IES -> TM-33 -> LDT -> TM-33"));
      }
    } else {
      const Photometry back = read_ldt(format_ldt(x), "back.ldt");
      worst_ldt = std::max(worst_ldt, flux_and_candela(p, back, 1e-6, "LDT -> TM-33 -> LDT"));
      const Photometry i = read_ies(format_ies(j), "j.ies");
      worst_ies = std::max(worst_ies, flux_and_candela(p, i, 1e-6, "LDT -> TM-33 -> IES"));
    }
    ++n;
  }
  EXPECT_GE(n, 60u);
  std::printf("TM-33 round trips over %zu real files: worst relative flux change via IES %.3g, via LDT %.3g\n", n,
              worst_ies, worst_ldt);
}

TEST(Tm33, FormatFollowsExtensionAndContent) {
  EXPECT_EQ(format_from_extension("a.XML"), PhotometryFormat::tm33_xml);
  EXPECT_EQ(format_from_extension("a.json"), PhotometryFormat::tm33_json);
  EXPECT_FALSE(format_from_extension("a.txt"));
  EXPECT_EQ(detect_format("a.txt", "\xEF\xBB\xBF  <?xml version=\"1.0\"?><IESTM33/>"), PhotometryFormat::tm33_xml);
  EXPECT_EQ(detect_format("a.txt", "\n{\"IESTM33-22\": {}}"), PhotometryFormat::tm33_json);
  EXPECT_EQ(detect_format("a.txt", "IESNA:LM-63-2002\n"), PhotometryFormat::ies);
}

TEST(Tm33, WriterIsAtomicAndRefusesBadTables) {
  const fs::path out = lumx_test::unique_temp_path("tm33_atomic.xml");
  const Photometry p = read_fixture("troffer_tm33_18.xml");
  write_photometry(p, out.string());
  const std::string before = lumx_test::read_text(out);
  EXPECT_EQ(read_photometry(out.string()).candela, p.candela);
  Photometry bad = p;
  bad.candela[3] = std::nan("");
  EXPECT_THROW(write_photometry(bad, out.string()), Error);
  EXPECT_EQ(lumx_test::read_text(out), before);
  fs::remove(out);
}

// ---- bad input ----

namespace {

/// The error a bad document raises (fails the test if it parses).
Diagnostic error_of(const std::string& text, bool json = false) {
  try {
    if (json) read_tm33_json(text, "bad.json");
    else read_tm33_xml(text, "bad.xml");
  } catch (const Error& e) {
    return e.diagnostic();
  }
  ADD_FAILURE() << "no error for:\n" << text.substr(0, 400);
  return {};
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

}  // namespace

TEST(Tm33BadInput, ErrorsAreLocatedByLineAndElement) {
  const std::string good = lumx_test::read_text(fixture("troffer_tm33_18.xml"));
  struct Case {
    std::string text, field, words;
  };
  const Case cases[] = {
      {replace(good, "<NumberHorz>3</NumberHorz>", "<NumberHorz>4</NumberHorz>"), "NumberHorz", "states 4"},
      {replace(good, "<NumberHorz>3</NumberHorz>", "<NumberHorz>1000000000</NumberHorz>"), "NumberHorz", "not an integer in"},
      {replace(good, "<NumberMeasured>21</NumberMeasured>", "<NumberMeasured>-5</NumberMeasured>"), "NumberMeasured", "not an integer"},
      {replace(good, ">830</IntData>", ">8,30</IntData>"), "IntData", "not a finite number"},
      {replace(good, ">830</IntData>", ">nan</IntData>"), "IntData", "not a finite number"},
      {replace(good, "<IntData h=\"45\" v=\"30\">", "<IntData h=\"45\" v=\"15\">"), "IntData", "appears twice"},
      {replace(good, "<IntData h=\"45\" v=\"30\">", "<IntData v=\"30\">"), "IntData@h", "missing"},
      {replace(good, "<Type>IES_C</Type>", "<Type>IES_D</Type>"), "Type", "not one of"},
      {replace(good, "<Tilt angle=\"45\">", "<Tilt angle=\"-45\">"), "Tilt@angle", "increase"},
      {replace(good, "<Quantity>2</Quantity>", "<Quantity>2.5</Quantity>"), "Quantity", "not an integer"},
      {replace(good, "<IESTM33>", "<IESTM34>").replace(good.rfind("</IESTM33>") + 0, 10, "</IESTM34>"), "root", "not a TM-33 root"},
      {replace(good, "</LuminousIntensity>", "</LuminousIntensty>"), "XML", ""},
  };
  for (const auto& c : cases) {
    const Diagnostic d = error_of(c.text);
    EXPECT_EQ(d.file, "bad.xml");
    EXPECT_GT(d.line, 0) << d.str();
    EXPECT_EQ(d.field, c.field) << d.str();
    EXPECT_NE(d.message.find(c.words), std::string::npos) << d.str();
  }
  // The first IntData is on the line the error names.
  const Diagnostic d = error_of(replace(good, ">1000</IntData>", ">x</IntData>"));
  const int line = 1 + static_cast<int>(std::count(good.begin(), good.begin() + static_cast<long>(good.find("<IntData")), '\n'));
  EXPECT_EQ(d.line, line);
}

TEST(Tm33BadInput, JsonErrorsNameTheirPointer) {
  const std::string good = lumx_test::read_text(fixture("downlight_tm33_23.json"));
  Diagnostic d = error_of(replace(good, "\"NumberVert\": 7", "\"NumberVert\": \"seven\""), true);
  EXPECT_EQ(d.field, "/IESTM33-22/Emitter/0/LuminousData/LuminousIntensity/NumberVert") << d.str();
  d = error_of(replace(good, "{\"@h\": 0, \"@v\": 60, \"#text\": 200}", "{\"@h\": 0, \"@v\": 60, \"#text\": [200]}"), true);
  EXPECT_NE(d.field.find("/IntData/2"), std::string::npos) << d.str();
  d = error_of(good.substr(0, good.size() / 2), true);  // truncated: a syntax error with its line
  EXPECT_EQ(d.field, "JSON");
  EXPECT_GT(d.line, 10);
  d = error_of("[1, 2]", true);
  EXPECT_EQ(d.field, "/");
}

TEST(Tm33BadInput, DtdsAreRefusedSoNoEntityIsExpanded) {
  const std::string laughs =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [<!ENTITY lol \"lol\"><!ENTITY lol2 \"&lol;&lol;&lol;&lol;\">]>\n"
      "<IESTM33><Header><Description>&lol2;</Description></Header></IESTM33>\n";
  const Diagnostic d = error_of(laughs);
  EXPECT_EQ(d.line, 2);
  EXPECT_EQ(d.field, "DOCTYPE");
  const std::string external =
      "<?xml version=\"1.0\"?><!DOCTYPE r [<!ENTITY x SYSTEM \"file:///etc/passwd\">]><IESTM33>&x;</IESTM33>";
  EXPECT_EQ(error_of(external).field, "DOCTYPE");
}

TEST(Tm33BadInput, DocumentsWithoutAnIntensityTableAreRefused) {
  // A horticultural document with photon intensity only (the model holds luminous intensity).
  const std::string photon =
      "<IESTM33><Version>1.1</Version><Header/><Emitter><Quantity>1</Quantity><PhotonData><MinWavelength>400"
      "</MinWavelength><MaxWavelength>700</MaxWavelength><PhotonIntensity><NumberMeasured>2</NumberMeasured>"
      "<NumberHorz>1</NumberHorz><NumberVert>2</NumberVert><IntData h=\"0\" v=\"0\">1</IntData>"
      "<IntData h=\"0\" v=\"90\">0</IntData></PhotonIntensity></PhotonData></Emitter></IESTM33>";
  EXPECT_EQ(error_of(photon).field, "LuminousData");
  EXPECT_EQ(error_of("<IESTM33><Version>1.0</Version></IESTM33>").field, "Emitter");
  // Deep nesting is refused before it is walked.
  std::string deep = "<IESTM33><Emitter>";
  for (int i = 0; i < 100; ++i) deep += "<a>";
  for (int i = 0; i < 100; ++i) deep += "</a>";
  deep += "</Emitter></IESTM33>";
  EXPECT_NE(error_of(deep).message.find("nest deeper"), std::string::npos);
}

TEST(Tm33BadInput, EveryTruncationIsALocatedError) {
  for (const char* name : {"troffer_tm33_18.xml", "downlight_tm33_23.json"}) {
    const std::string good = lumx_test::read_text(fixture(name));
    const bool json = std::string(name).find(".json") != std::string::npos;
    std::size_t errors = 0;
    for (std::size_t cut = 0; cut + 2 < good.size(); cut += 7) {
      try {
        if (json) read_tm33_json(good.substr(0, cut), "cut");
        else read_tm33_xml(good.substr(0, cut), "cut");
      } catch (const Error& e) {
        ++errors;
        EXPECT_TRUE(e.diagnostic().line > 0 || !e.diagnostic().field.empty()) << e.what();
      }
    }
    EXPECT_EQ(errors, (good.size() - 3) / 7 + 1) << name;  // every cut is an error, and only lumx::Error
  }
}

TEST(Tm33BadInput, MutationsAndHostileNumbersLoadSanelyOrFailWithLumxErrors) {
  // Whatever reads must also write and read back to the same table (the writer accepts all the reader
  // produces).
  auto through = [](bool json) {
    return [json](const std::string& s) {
      const Photometry p = json ? read_tm33_json(s, "m.json") : read_tm33_xml(s, "m.xml");
      const Photometry q = json ? read_tm33_json(format_tm33_json(p), "w.json") : read_tm33_xml(format_tm33_xml(p), "w.xml");
      if (q.candela != p.candela || q.horizontal_deg != p.horizontal_deg) ADD_FAILURE() << "write-read changed the table";
      return p;
    };
  };
  const std::string xml = lumx_test::read_text(fixture("troffer_tm33_18.xml"));
  const std::string json = lumx_test::read_text(fixture("downlight_tm33_23.json"));
  lumx_bad::never_crash_sweep(through(false), xml, "troffer_tm33_18.xml", 0x7333, 400);
  lumx_bad::never_crash_sweep(through(true), json, "downlight_tm33_23.json", 0x7334, 400);
  lumx_bad::token_sweep(through(false), xml, "troffer_tm33_18.xml");
  lumx_bad::token_sweep(through(true), json, "downlight_tm33_23.json");
}

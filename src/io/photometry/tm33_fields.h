// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: TM-33 names shared by the reader and the writer — header fields that are LM-63 keywords,
// the identifiers of lumx's own CustomData blocks, and the element order of the TM-33-23 schema.
#pragma once

#include <lumx/version.h>

#include <cstring>
#include <string>

LUMX_NAMESPACE_BEGIN
namespace tm33 {

/// CustomData/UniqueIdentifier of the block holding LM-63 fields TM-33 has no element for.
inline constexpr const char* kLm63Block = "lumx:lm63";
/// CustomData/UniqueIdentifier of the block holding EULUMDAT fields TM-33 has no element for.
inline constexpr const char* kEulumdatBlock = "lumx:eulumdat";

/// The LM-63 keyword a TM-33 Header element carries, or nullptr.
inline const char* header_keyword(const std::string& element) {
  static const char* const kMap[][2] = {{"Manufacturer", "MANUFAC"}, {"CatalogNumber", "LUMCAT"},
                                        {"Description", "LUMINAIRE"}, {"Laboratory", "TESTLAB"},
                                        {"ReportNumber", "TEST"},      {"ReportDate", "ISSUEDATE"}};
  for (const auto& m : kMap)
    if (element == m[0]) return m[1];
  return nullptr;
}

/// The Header element an LM-63 keyword maps to, or nullptr.
inline const char* header_element(const std::string& keyword) {
  static const char* const kMap[][2] = {{"MANUFAC", "Manufacturer"}, {"LUMCAT", "CatalogNumber"},
                                        {"LUMINAIRE", "Description"}, {"TESTLAB", "Laboratory"},
                                        {"TEST", "ReportNumber"},      {"ISSUEDATE", "ReportDate"}};
  for (const auto& m : kMap)
    if (keyword == m[0]) return m[1];
  return nullptr;
}

/// Position of `child` in the TM-33-23 sequence of `parent` (unknown names sort last, in file order).
inline int schema_rank(const std::string& parent, const std::string& child) {
  static const char* const kRoot[] = {"Version", "Header", "Luminaire", "Equipment", "Emitter", "CustomData", nullptr};
  static const char* const kHeader[] = {"Manufacturer", "CatalogNumber", "GTIN", "Description", "Laboratory",
                                        "ReportNumber", "ReportDate", "DocumentCreator", "DocumentCreationDate",
                                        "UniqueIdentifier", "Comment", "Reference", "MoreInfoURI", nullptr};
  static const char* const kLuminaire[] = {"Dimensions", "Shape", "NumEmitter", nullptr};
  static const char* const kEmitter[] = {
      "Quantity", "Description", "CatalogNumber", "RatedLumens", "InputWattage", "PowerFactor", "BallastFactor",
      "TiltAngles", "ColorTemperature", "ColorRendering", "Duv", "SPRatio", "DataGeneration", "LuminousData",
      "RadiantData", "PhotonData", "SpectralData", "AngularColor", "IllumData", "IrradData", "PFDData",
      "SpecIrradData", "Channels", "EmissionAreas", "EmitterCenter", "Regulatory", nullptr};
  static const char* const kLuminousData[] = {"LuminousIntensity", "LuminousFlux", nullptr};
  static const char* const kIntensity[] = {"AbsolutePhotometry", "Symm", "Multiplier", "NumberMeasured",
                                           "NumberHorz", "NumberVert", "IntData", nullptr};
  static const char* const kCustom[] = {"Name", "UniqueIdentifier", nullptr};
  const char* const* order = nullptr;
  if (parent == "IESTM33" || parent == "IESTM33-22" || parent == "LuminaireOpticalData") order = kRoot;
  else if (parent == "Header") order = kHeader;
  else if (parent == "Luminaire") order = kLuminaire;
  else if (parent == "Emitter") order = kEmitter;
  else if (parent == "LuminousData") order = kLuminousData;
  else if (parent == "LuminousIntensity") order = kIntensity;
  else if (parent == "CustomData") order = kCustom;
  if (!order) return 0;
  for (int i = 0; order[i]; ++i)
    if (child == order[i]) return i;
  return 1000;
}

}  // namespace tm33
LUMX_NAMESPACE_END

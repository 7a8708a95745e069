// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/tm33_io.h — reading and writing IES TM-33 / ATLA S001 / UNI 11733 luminaire optical data.
//
// TM-33 is an XML document (ATLA S001 also defines a JSON form of the same tree). The reader accepts the
// three root elements in use — "IESTM33" (TM-33-18, Version 1.0), "LuminaireOpticalData" (ATLA S001)
// and "IESTM33-22" (TM-33-23, Version 1.1) — in XML or JSON, and maps the first emitter's luminous
// intensity table, the header, the luminaire and every emitter to the photometry model. What the model
// has no field for (spectral, radiant, photon and colour blocks, equipment, regulatory flags, custom
// data) is kept as data in Photometry::tm33 and written back by the writer. Which document version each
// field follows, and the JSON mapping, are in docs/tm33.md.
//
// Errors are lumx::Error located by line (XML) or JSON pointer (JSON, in the field) and element name.
// Documents with a DTD are refused (no entity expansion), counts are checked against the values present
// and against ReadLimits before anything is sized from them.
#pragma once

#include <lumx/io/photometry_io.h>

#include <string>
#include <string_view>

LUMX_NAMESPACE_BEGIN

/// Parses a TM-33 document in XML. `name` is used in diagnostics.
Photometry read_tm33_xml(std::string_view text, const std::string& name, const ReadOptions& options = {});
/// Parses a TM-33 document in its JSON form (docs/tm33.md). `name` is used in diagnostics.
Photometry read_tm33_json(std::string_view text, const std::string& name, const ReadOptions& options = {});

/// TM-33 XML text for `p`: luminous intensity in absolute cd with multiplier 1, the stored subset with
/// its symmetry (Symm, TM-33-23 only), header, luminaire and one Emitter per lamp set; kept elements in
/// place. Throws lumx::Error if `p` cannot be expressed (inconsistent table sizes, non-finite values).
std::string format_tm33_xml(const Photometry& p, const Tm33WriteOptions& options = {});
/// The same document in its JSON form.
std::string format_tm33_json(const Photometry& p, const Tm33WriteOptions& options = {});

LUMX_NAMESPACE_END

// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/metrics_commands.h — what `lumx info` adds about a photometry's metrics (zonal lumens, CIE
// flux code, BUG rating, spacing criterion, luminance table, UGR table) and the `lumx plot --kind`
// diagrams other than the polar curve.
#pragma once

#include "commands.h"

#include <lumx/photometry/photometry.h>

#include <nlohmann/json.hpp>

namespace lumx_cli {

/// The metrics of `p` as JSON; a metric the data cannot give (a point source has no luminance or UGR)
/// is null with its reason under "<name>_error".
nlohmann::json metrics_json(const lumx::Photometry& p);

/// The metrics summarised in a few lines of plain text (stdout).
void print_metrics_summary(const lumx::Photometry& p);

/// `lumx plot FILE --kind isolux|isocandela|cone|ugr`: draws the diagram and prints what it shows.
int run_metric_plot(const PlotArgs& a, const lumx::Photometry& p);

}  // namespace lumx_cli

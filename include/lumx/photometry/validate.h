// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/validate.h — strict validation of a Photometry, as its own pass after parsing.
//
// Parsing accepts what real files do (and warns); validation judges the result against the standards
// and against physics: table consistency, finite and non-negative intensities, a single value at each
// pole, non-zero flux, plausible lamp and ballast data, and (for EULUMDAT) the stated downward flux
// fraction and light output ratio against the ones computed from the table. Findings are located by the
// source lines the reader recorded, when it recorded them. `lumx check` = read + validate.
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/photometry/photometry.h>

#include <vector>

LUMX_NAMESPACE_BEGIN

/// All findings for `p` (errors and warnings), in a stable order. Never throws for bad data.
std::vector<Diagnostic> validate(const Photometry& p);

LUMX_NAMESPACE_END

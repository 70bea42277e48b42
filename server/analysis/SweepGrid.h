// Parameter grids for gi-bench sweep, derived from a technique's ParamTable (never hand-written).
//
// A full Cartesian product of a dozen knobs explodes, so the grid varies one knob at a time around
// the defaults: the default point first, then each knob in table order with its
// ParamTable::sweepValues (numeric knobs: `steps` values across the range, geometric for logScale;
// enums: every option; bools: both). Within a knob the values above the default come first in
// ascending order, then the values below it in descending order, so the sweep walks outward from
// the default on each side; a caller can then stop a side once a point gets too slow.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/Param.h"

namespace gis {

struct GridPoint {
    std::string knob;      ///< the varied parameter; empty for the default point
    nlohmann::json value;  ///< its value (null for the default point)
    int side = 0;          ///< +1 above the default, -1 below, 0 for enums, bools and the default point
    nlohmann::json params; ///< every parameter of the table, {name: value}
};

/// The default point plus the one-at-a-time variations of `knobs` (empty = every knob of the table).
/// Values equal to the default are dropped. Throws InputError naming an unknown knob.
std::vector<GridPoint> oneAtATimeGrid(const ParamTable& table, int steps,
                                      const std::vector<std::string>& knobs = {});

/// {name: default} for every parameter of the table.
nlohmann::json defaultParams(const ParamTable& table);

/// The parameters of `params` that differ from the table's defaults ("vpl_grid=8 kernel=disk"), or
/// "defaults".
std::string describeChanges(const ParamTable& table, const nlohmann::json& params);

} // namespace gis

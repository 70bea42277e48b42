// How many VPLs a frame asks for, from the technique's own capability (gi/Catalog.h
// TechniqueInfo::vplEstimate): what --max-vpls bounds and the refinement predictor scales by.
#pragma once

#include "frame/FrameState.h"

namespace gis {

/// The most VPLs (or virtual lights) `state` renders with; 0 for a technique without VPLs.
long vplEstimate(const FrameState& state);

} // namespace gis

// Renderer-level parameters, shared by every technique: declared once here.
#pragma once

#include "core/Param.h"

namespace gis {

const ParamTable& frameParamTable();

} // namespace gis

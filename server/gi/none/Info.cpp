// The catalog entry of `none` (direct light only): no parameters, no VPLs. GL-free (gi/Catalog.h).
#include "gi/Catalog.h"

namespace gis {

TechniqueInfo noIndirectInfo() {
    TechniqueInfo info{"none", "direct light only (no indirect illumination)", "baseline", ParamTable{}};
    info.readsRsm = false;
    return info;
}

} // namespace gis

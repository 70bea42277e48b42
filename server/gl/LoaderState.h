// Process-wide GL entry-point state shared by the platform implementations (internal to server/gl).
#pragma once

#include "gl/GlApi.h"
#include "gl/Platform.h"

namespace gis::gl::detail {
/// Loads the entry points for `backend` the first time; throws if another backend loaded them.
void ensureEntryPoints(Backend backend, GetProcFn getProc);
void fillContextInfo(ContextInfo& info);
} // namespace gis::gl::detail

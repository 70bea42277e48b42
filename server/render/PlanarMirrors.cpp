#include "render/PlanarMirrors.h"

namespace gis {

struct PlanarMirrors::Impl {};

PlanarMirrors::PlanarMirrors() : mImpl(std::make_unique<Impl>()) {}
PlanarMirrors::~PlanarMirrors() = default;

void PlanarMirrors::execute(const ReflectionInputs&, const ParamSet&, const gl::Framebuffer&, gl::PassTimer&, Counters&) {}

} // namespace gis

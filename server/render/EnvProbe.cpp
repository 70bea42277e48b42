#include "render/EnvProbe.h"

namespace gis {

struct EnvProbe::Impl {};

EnvProbe::EnvProbe() : mImpl(std::make_unique<Impl>()) {}
EnvProbe::~EnvProbe() = default;

void EnvProbe::execute(const ReflectionInputs&, const ParamSet&, const gl::Framebuffer&, gl::PassTimer&, Counters&) {}

} // namespace gis

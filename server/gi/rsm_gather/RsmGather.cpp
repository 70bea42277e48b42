#include "gi/rsm_gather/RsmGather.h"

#include <algorithm>

#include "gl/ShaderShared.h"

namespace gis {

RsmGather::GatherProgram::GatherProgram(gl::Program built)
    : program(std::move(built)),
      minDistance(program.optionalLocation("uMinDistance")) /* point kernel only */,
      vplCount(program.location("uVplCount")), vplFirst(program.location("uVplFirst")),
      vplPhase(program.location("uVplPhase")), vplStride(program.location("uVplStride")),
      allVpls(program.storageBlock("VplAll")), position(program.textureUnit("gPosition")),
      normal(program.textureUnit("gNormal")), albedo(program.textureUnit("gAlbedo")),
      specular(program.textureUnit("gSpecular")), transport(program), shadows(program) {}

RsmGather::RsmGather() {
    mGather = KernelPrograms<GatherProgram>(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "gi/rsm_gather/gather.frag"}});
    mEmptyVao = gl::VertexArray::create();
}

void RsmGather::resize(int width, int height) {
    mIndirect.resize(width, height, "rsm_gather indirect");
}

void RsmGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                        Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mShadows.render(in, params, mVpls.buffer(), vplCount, timer, counters);

    {
        gl::Pass pass(timer, "vpl_gather");
        pass.target(mIndirect.framebuffer, in.width, in.height).clearColor(1);
        if (vplCount > 0) {
            const GatherProgram& g = mGather.get(vplKernel(params));
            const bool glossy = in.glossy && in.find("gbuffer.specular") != nullptr;
            pass.use(g.program).set(g.minDistance, static_cast<float>(params.getFloat("min_distance")));
            mShadows.bind(pass, g.shadows, in, params);
            pass.texture(g.position, in.get("gbuffer.position"))
                .texture(g.normal, in.get("gbuffer.normal"))
                .texture(g.albedo, in.get("gbuffer.albedo"));
            g.transport.set(pass, params, glossy, in.glossyMinRoughness, &mVpls.glossyBuffer());
            if (glossy) pass.texture(g.specular, in.get("gbuffer.specular"));
            pass.blendAdd();
            if (in.vplParts > 1) {
                // One of the refinement's VPL parts: one draw striding over the whole buffer (the
                // batches' uniform block is bound but not read).
                const int parts = in.vplParts;
                const int part = std::clamp(in.vplPart, 0, parts - 1);
                pass.buffer(g.allVpls, mVpls.buffer());
                bool drawn = false;
                mVpls.forEachBatch([&](int) {
                    if (drawn || part >= vplCount) return;
                    pass.set(g.vplCount, vplCount)
                        .set(g.vplFirst, 0)
                        .set(g.vplPhase, part)
                        .set(g.vplStride, parts)
                        .drawFullscreen(mEmptyVao);
                    drawn = true;
                });
                counters["vpl_batches"] = drawn ? 1 : 0;
                counters["vpl_part"] = part;
                counters["vpl_parts"] = parts;
            } else {
                int first = 0;
                counters["vpl_batches"] = mVpls.forEachBatch([&](int count) {
                    pass.set(g.vplCount, count)
                        .set(g.vplFirst, first)
                        .set(g.vplPhase, 0)
                        .set(g.vplStride, 1)
                        .drawFullscreen(mEmptyVao);
                    first += count;
                });
            }
        }
    }
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis

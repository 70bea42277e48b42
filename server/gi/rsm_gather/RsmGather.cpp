#include "gi/rsm_gather/RsmGather.h"

#include <algorithm>

#include "gi/common/ParamSpecs.h"
#include "gl/ShaderShared.h"

namespace gis {

RsmGather::GatherProgram::GatherProgram(gl::Program built)
    : program(std::move(built)),
      minDistance(program.optionalLocation("uMinDistance")) /* point kernel only */,
      vplCount(program.location("uVplCount")), vplFirst(program.location("uVplFirst")),
      vplPhase(program.location("uVplPhase")), vplStride(program.location("uVplStride")),
      position(program.textureUnit("gPosition")), normal(program.textureUnit("gNormal")),
      albedo(program.textureUnit("gAlbedo")), specular(program.textureUnit("gSpecular")), transport(program),
      shadows(program) {}

RsmGather::RsmGather() {
    const std::vector<gl::ShaderStage> stages = {{GL_VERTEX_SHADER, "render/fullscreen.vert"},
                                                 {GL_FRAGMENT_SHADER, "gi/rsm_gather/gather.frag"}};
    mGather = KernelPrograms<GatherProgram>(stages, {{"GIS_VPL_SHADOWED", "0"}});
    mShadowedGather = KernelPrograms<GatherProgram>(stages, {{"GIS_VPL_SHADOWED", "1"}});
    mEmptyVao = gl::VertexArray::create();
}

void RsmGather::resize(int width, int height) {
    mIndirect.resize(width, height, "rsm_gather indirect");
}

void RsmGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                        Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    const bool shadowed = mShadows.render(in, params, mVpls.buffer(), vplCount, timer, counters) > 0;
    // The VPLs and their shadow maps are whole: input may stop the frame before the gather.
    if (in.interrupted()) return;
    if (in.vplParts > 1) mVpls.preparePart(in.vplPart, in.vplParts, timer);

    {
        gl::Pass pass(timer, "vpl_gather");
        pass.target(mIndirect.framebuffer, in.width, in.height).clearColor(1);
        if (vplCount > 0) {
            const GatherProgram& g = (shadowed ? mShadowedGather : mGather).get(vplKernel(params));
            const bool glossy = in.glossy && in.find("gbuffer.specular") != nullptr;
            pass.use(g.program).set(g.minDistance, vplMinDistance(params, in.sceneSize));
            mShadows.bind(pass, g.shadows, in, params);
            pass.texture(g.position, in.get("gbuffer.position"))
                .texture(g.normal, in.get("gbuffer.normal"))
                .texture(g.albedo, in.get("gbuffer.albedo"));
            g.transport.set(pass, params, in.sceneSize, glossy, in.glossyMinRoughness, &mVpls.glossyBuffer());
            if (glossy) pass.texture(g.specular, in.get("gbuffer.specular"));
            pass.blendAdd();
            // A VPL part (refinement) gathers every vplParts-th VPL, laid out contiguously.
            const int parts = std::max(1, in.vplParts);
            const int part = std::clamp(in.vplPart, 0, parts - 1);
            // In refinement the gather goes in pieces that input can stop between (a VPL part's
            // gather is a whole slice): batches, or bands of each batch (gatherCut).
            int batches = 0;
            const bool whole = mVpls.forEachPiece(
                parts > 1, in.interruptCheck,
                [&](int count, int first, int cuts) {
                    pass.set(g.vplCount, count)
                        .set(g.vplFirst, first)
                        .set(g.vplPhase, part)
                        .set(g.vplStride, parts);
                    return pass.drawFullscreenInBands(mEmptyVao, in.interruptCheck, cuts);
                },
                batches);
            counters["vpl_batches"] = batches;
            if (parts > 1) {
                counters["vpl_part"] = part;
                counters["vpl_parts"] = parts;
            }
            if (!whole) return;
        }
    }
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis

#include "gi/common/VplGrid.h"

#include <algorithm>
#include <cmath>

#include "gi/common/BiasCompensation.h"
#include "gi/common/ParamSpecs.h"
#include "gl/ShaderShared.h"

namespace gis {

std::vector<std::pair<std::string, std::string>>
kernelDefines(VplKernel kernel, const std::vector<std::pair<std::string, std::string>>& defines) {
    auto all = defines;
    all.emplace_back("GIS_VPL_KERNEL", kernel == VplKernel::Disk ? "GIS_KERNEL_DISK" : "GIS_KERNEL_POINT");
    return all;
}

VplTransportHandles::VplTransportHandles(const gl::Program& program)
    : invClampB(program.optionalLocation("uVplInvClampB")), hasGlossy(program.declares("uGlossy")) {
    if (hasGlossy) {
        glossy = program.optionalLocation("uGlossy");
        glossyMinRoughness = program.optionalLocation("uGlossyMinRoughness");
        glossyVpls = program.optionalStorageBlock("VplGlossyBuffer");
    }
}

void VplTransportHandles::set(gl::Pass& pass, const ParamSet& params, float sceneSize, bool glossyOn,
                              float minRoughness, const gl::Buffer* glossyData) const {
    pass.set(invClampB, vplInverseClampB(params, sceneSize));
    if (!hasGlossy) return;
    pass.set(glossy, glossyOn ? 1 : 0).set(glossyMinRoughness, minRoughness);
    if (glossyOn && glossyData) pass.buffer(glossyVpls, *glossyData);
}

VplGrid::VplGrid() {
    gl::Program p = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/vpl_extract.comp"}});
    mExtract = {{},
                p.location("uGrid"),
                p.location("uRsmSize"),
                p.location("uView"),
                p.location("uOffset"),
                p.textureUnit("gRsmPosition"),
                p.textureUnit("gRsmNormal"),
                p.textureUnit("gRsmFlux"),
                p.textureUnit("gRsmSpecular"),
                p.storageBlock("VplOut"),
                p.storageBlock("VplGlossyOut")};
    mExtract.program = std::move(p);
    gl::Program q = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/vpl_interleave.comp"}});
    mInterleave = {{},
                   q.location("uPartCount"),
                   q.location("uPart"),
                   q.location("uParts"),
                   q.storageBlock("VplIn"),
                   q.storageBlock("VplOut")};
    mInterleave.program = std::move(q);
}

std::vector<int> splitVplGrid(int grid, const std::vector<double>& viewFlux, int views, int rsmSide) {
    std::vector<int> sides(static_cast<size_t>(std::max(views, 0)), 0);
    if (views <= 0 || grid <= 0) return sides;
    const int maxSide = std::max(rsmSide, 1);
    if (views == 1) {
        sides[0] = std::clamp(grid, 1, maxSide);
        return sides;
    }
    double total = 0.0;
    for (int v = 0; v < views; ++v) {
        const double f = v < static_cast<int>(viewFlux.size()) ? viewFlux[static_cast<size_t>(v)] : 0.0;
        if (std::isfinite(f) && f > 0.0) total += f;
    }
    const double budget = double(grid) * double(grid);
    for (int v = 0; v < views; ++v) {
        const double f = v < static_cast<int>(viewFlux.size()) ? viewFlux[static_cast<size_t>(v)] : 0.0;
        // No flux anywhere (every light sees only empty space): an even split, so the set is not empty
        // on account of the measurement alone.
        const double share = total > 0.0 ? (std::isfinite(f) && f > 0.0 ? f / total : 0.0) : 1.0 / views;
        if (!(share > 0.0)) continue;
        const int side = static_cast<int>(std::lround(std::sqrt(budget * share)));
        sides[static_cast<size_t>(v)] = std::clamp(side, 1, maxSide);
    }
    return sides;
}

int VplGrid::extract(const FrameInputs& in, int grid, gl::PassTimer& timer, Counters& counters) {
    const int views = in.lightEnabled ? in.lightViews : 0;
    const std::vector<int> sides = splitVplGrid(grid, in.viewFlux, views, in.rsmSize);
    // The VPLs depend on the RSMs and the split alone: unchanged light views (an orbit, the tiles
    // and VPL parts of a refinement step) keep the last extraction. With several views it cost
    // 16 ms of a 25 ms VPL part on cornell-colored at 960 x 800.
    if (in.lightViewsReused && mExtracted && sides == mExtractedSides && in.rsmSize == mExtractedRsmSize) {
        counters["vpl_count"] = mCount;
        counters["vpls_reused"] = 1;
        return mCount;
    }
    mExtracted = false;
    mCount = 0;
    for (int side : sides) mCount += side * side;
    counters["vpl_count"] = mCount;
    const GLsizeiptr bytes = static_cast<GLsizeiptr>(std::max(mCount, 1)) * sizeof(shader::Vpl);
    if (mVpls.size() < bytes) mVpls = gl::Buffer::create(bytes);
    const GLsizeiptr glossyBytes = static_cast<GLsizeiptr>(std::max(mCount, 1)) * sizeof(shader::VplGlossy);
    if (mGlossy.size() < glossyBytes) mGlossy = gl::Buffer::create(glossyBytes);
    if (mCount == 0) return 0;

    const ExtractProgram& e = mExtract;
    gl::Pass pass(timer, "vpl_extract");
    pass.use(e.program).set(e.rsmSize, in.rsmSize);
    pass.texture(e.position, in.get("lights.rsm.position"))
        .texture(e.normal, in.get("lights.rsm.normal"))
        .texture(e.flux, in.get("lights.rsm.flux"))
        .texture(e.specular, in.find("lights.rsm.specular"));
    pass.buffer(e.vpls, mVpls).buffer(e.glossy, mGlossy);
    int offset = 0;
    for (int v = 0; v < views; ++v) {
        const int side = sides[static_cast<size_t>(v)];
        if (side <= 0) continue;
        pass.set(e.grid, side).set(e.view, v).set(e.offset, offset);
        pass.dispatch((side * side + 63) / 64);
        offset += side * side;
    }
    pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    mExtracted = true;
    mExtractedSides = sides;
    mExtractedRsmSize = in.rsmSize;
    return mCount;
}

VplBatches::VplBatches() : mView(gl::BufferTexture::create()) {}

int VplBatches::forEach(const gl::Buffer& vpls, int count,
                        const std::function<void(int batchCount, int first)>& draw) {
    int batches = 0;
    for (int first = 0; first < count; first += GIS_MAX_VPLS_PER_BATCH, ++batches) {
        const int n = std::min(GIS_MAX_VPLS_PER_BATCH, count - first);
        mView.view(vpls, GL_RGBA32F,
                   static_cast<GLintptr>(first) * static_cast<GLintptr>(sizeof(shader::Vpl)),
                   static_cast<GLsizeiptr>(n) * static_cast<GLsizeiptr>(sizeof(shader::Vpl)));
        glBindTextureUnit(GIS_TEXTURE_VPLS, mView.id());
        draw(n, first);
    }
    return batches;
}

GatherCut gatherCut(int batches) {
    // Rounded to the nearest, so that the pieces stay within about 3/4 to 3/2 of kGatherPieces.
    GatherCut cut;
    const int n = std::max(batches, 1);
    if (n >= kGatherPieces)
        cut.batchesPerPiece = (n + kGatherPieces / 2) / kGatherPieces;
    else
        cut.cutsPerBatch = std::max(1, (kGatherPieces + n / 2) / n);
    return cut;
}

bool VplBatches::forEachPiece(const gl::Buffer& vpls, int count, const std::function<bool()>& stop,
                              const std::function<bool(int batchCount, int first, int cuts)>& draw,
                              int& batches) {
    const int total = (std::max(count, 0) + GIS_MAX_VPLS_PER_BATCH - 1) / GIS_MAX_VPLS_PER_BATCH;
    const GatherCut cut = stop ? gatherCut(total) : GatherCut{};
    bool goOn = true;
    batches = 0;
    forEach(vpls, count, [&](int n, int first) {
        if (!goOn) return;
        ++batches;
        goOn = draw(n, first, cut.cutsPerBatch);
        if (goOn && stop && batches < total && batches % cut.batchesPerPiece == 0) goOn = !stop();
    });
    return goOn;
}

int VplGrid::preparePart(int part, int parts, gl::PassTimer& timer) {
    parts = std::max(parts, 1);
    part = std::clamp(part, 0, parts - 1);
    // The VPLs part, part + parts, ... below mCount.
    mPartCount = mCount / parts + (part < mCount % parts ? 1 : 0);
    if (mPartCount == 0) return 0;
    const GLsizeiptr bytes = static_cast<GLsizeiptr>(mPartCount) * sizeof(shader::Vpl);
    if (mPartVpls.size() < bytes) mPartVpls = gl::Buffer::create(bytes);
    gl::Pass pass(timer, "vpl_interleave");
    pass.use(mInterleave.program)
        .set(mInterleave.partCount, mPartCount)
        .set(mInterleave.part, part)
        .set(mInterleave.parts, parts);
    pass.buffer(mInterleave.in, mVpls).buffer(mInterleave.out, mPartVpls);
    pass.dispatch((mPartCount + 63) / 64);
    pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    return mPartCount;
}

bool VplGrid::forEachPiece(bool part, const std::function<bool()>& stop,
                           const std::function<bool(int batchCount, int first, int cuts)>& draw,
                           int& batches) {
    return part ? mBatches.forEachPiece(mPartVpls, mPartCount, stop, draw, batches)
                : mBatches.forEachPiece(mVpls, mCount, stop, draw, batches);
}

} // namespace gis

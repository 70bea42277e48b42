#include "gi/common/EyeHierarchy.h"

#include <algorithm>

#include "core/Error.h"

namespace gis {

std::vector<EyeLevel> eyeLevelLayout(int width, int height, int coarsestSize, int* atlasWidth,
                                     int* atlasHeight) {
    GIS_ASSERT(width > 0 && height > 0 && coarsestSize > 0);
    std::vector<EyeLevel> levels;
    int w = width, h = height, columnY = 0;
    for (int l = 0;; ++l) {
        EyeLevel level{l == 0 ? 0 : width, l == 0 ? 0 : columnY, w, h};
        if (l > 0) columnY += h;
        levels.push_back(level);
        if (std::max(w, h) <= coarsestSize || l + 1 == GIS_MAX_EYE_LEVELS) break;
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    if (atlasWidth) *atlasWidth = width + (levels.size() > 1 ? levels[1].width : 0);
    if (atlasHeight) *atlasHeight = std::max(height, columnY);
    return levels;
}

EyeHierarchy::EyeHierarchy() {
    // Every pass is a full-screen draw clipped by the viewport to one level: llvmpipe shades
    // fragments faster than it runs image load/store compute (the mipmap: 36 ms as compute, 23 ms
    // as fragments at 512^2).
    const auto pass = [](const char* fragment) {
        return gl::Program::build(
            {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, fragment}});
    };
    mReduceFromPixels = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "gi/common/eye_mip_reduce.frag"}},
        {{"GIS_FROM_GBUFFER", "1"}});
    mReduce = pass("gi/common/eye_mip_reduce.frag");
    mFlagsProgram = pass("gi/common/eye_flags.frag");
    mReceivers = pass("gi/common/eye_receivers.frag");
    mUpsample = pass("gi/common/eye_upsample.frag");
    mResolve = pass("gi/common/eye_resolve.frag");
    mEmptyVao = gl::VertexArray::create();
    mUbo = gl::Buffer::create(sizeof(shader::EyeHierarchyUniforms));
    mCounts = gl::Buffer::create(sizeof(mLastCounts), nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
}

void EyeHierarchy::ensureLayout(int width, int height, int coarsestSize) {
    if (width == mWidth && height == mHeight && coarsestSize == mCoarsest) return;
    mLevels = eyeLevelLayout(width, height, coarsestSize, &mAtlasWidth, &mAtlasHeight);
    const int aw = mAtlasWidth, ah = mAtlasHeight;
    mGeoPosition = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    mGeoNormal = gl::Texture::create2D(GL_RGBA16F, aw, ah); // as precise as the G-buffer's normals
    mGeoAlbedo = gl::Texture::create2D(GL_RGBA16F, aw, ah);
    mDepthInfo = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    mNormalMin = gl::Texture::create2D(GL_RGBA16F, aw, ah);
    mNormalMax = gl::Texture::create2D(GL_RGBA16F, aw, ah);
    mFlags = gl::Texture::create2D(GL_R8UI, aw, ah);
    mDiscFlags = gl::Texture::create2D(GL_R8UI, aw, ah);
    mGeoFbo = gl::Framebuffer::create();
    const gl::Texture* geo[6] = {&mGeoPosition, &mGeoNormal, &mGeoAlbedo,
                                 &mDepthInfo,   &mNormalMin, &mNormalMax};
    for (int i = 0; i < 6; ++i) mGeoFbo.attachColor(i, *geo[i]);
    mGeoFbo.attachColor(6, mDiscFlags);
    mGeoFbo.finish(7, "eye hierarchy mipmaps");
    mFlagsFbo = gl::Framebuffer::create();
    mFlagsFbo.attachColor(0, mFlags);
    mFlagsFbo.finish(1, "eye refinement flags");
    mReconFbo = gl::Framebuffer::create();
    mIllumination = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    mReconstructed = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    mStencil = gl::Texture::create2D(GL_DEPTH24_STENCIL8, aw, ah);
    mIllumFbo = gl::Framebuffer::create();
    mIllumFbo.attachColor(0, mIllumination);
    mIllumFbo.attachDepthStencil(mStencil);
    mIllumFbo.finish(1, "multiresolution illumination buffer");
    mReconFbo.attachColor(0, mReconstructed);
    mReconFbo.finish(1, "reconstructed illumination");
    // Padding texels must read as empty even before the first frame writes them.
    const float zero[4] = {0, 0, 0, 0};
    for (const gl::Texture* t : {&mGeoPosition, &mGeoNormal, &mGeoAlbedo, &mDepthInfo, &mNormalMin,
                                 &mNormalMax, &mIllumination, &mReconstructed})
        glClearTexImage(t->id(), 0, GL_RGBA, GL_FLOAT, zero);
    const GLuint zeroU = 0;
    glClearTexImage(mFlags.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zeroU);
    glClearTexImage(mDiscFlags.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zeroU);
    mWidth = width;
    mHeight = height;
    mCoarsest = coarsestSize;
}

void EyeHierarchy::uploadUniforms(const ParamSet& params) {
    shader::EyeHierarchyUniforms u{};
    for (size_t l = 0; l < mLevels.size(); ++l)
        u.level[l] = glm::ivec4(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height);
    int options = 0;
    if (params.getBool("diagonal_refine")) options |= GIS_EYE_DIAGONAL;
    if (params.getEnum("depth_metric") == "derivative") options |= GIS_EYE_DEPTH_DERIVATIVE;
    if (params.getEnum("normal_metric") == "curvature") options |= GIS_EYE_CURVATURE;
    u.info = glm::ivec4(static_cast<int>(mLevels.size()), mWidth, mHeight, options);
    u.thresholds =
        glm::vec4(params.getFloat("depth_threshold"), params.getFloat("depth_derivative_threshold"),
                  params.getFloat("normal_threshold"), params.getFloat("curvature_threshold"));
    mUbo.upload(0, sizeof u, &u);
}

void EyeHierarchy::beginIlluminationPass(const FrameInputs& in, bool stencil) const {
    glBindFramebuffer(GL_FRAMEBUFFER, mIllumFbo.id());
    glViewport(0, 0, mAtlasWidth, mAtlasHeight);
    glBindTextureUnit(0, mGeoPosition.id());
    glBindTextureUnit(1, mGeoNormal.id());
    bindPixels(in);
    glBindVertexArray(mEmptyVao.id());
    if (stencil) {
        glEnable(GL_STENCIL_TEST);
        glStencilFunc(GL_EQUAL, 1, 0xFF);
        glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    }
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ZERO); // rgb accumulates, alpha marks data
}

void EyeHierarchy::endIlluminationPass() const {
    glDisable(GL_BLEND);
    glDisable(GL_STENCIL_TEST);
}

void EyeHierarchy::bindPixels(const FrameInputs& in) const {
    glBindTextureUnit(8, in.find("gbuffer.position")->id());
    glBindTextureUnit(9, in.find("gbuffer.normal")->id());
    glBindTextureUnit(10, in.find("gbuffer.albedo")->id());
}

void EyeHierarchy::bindUniforms() const {
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_EYE, mUbo.id());
}

void EyeHierarchy::build(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer) {
    ensureLayout(in.width, in.height, params.getInt("coarsest_size"));
    uploadUniforms(params);
    bindUniforms();

    timer.begin("eye_mipmap");
    glBindVertexArray(mEmptyVao.id());
    glBindFramebuffer(GL_FRAMEBUFFER, mGeoFbo.id());
    bindPixels(in);
    const gl::Texture* geo[6] = {&mGeoPosition, &mGeoNormal, &mGeoAlbedo,
                                 &mDepthInfo,   &mNormalMin, &mNormalMax};
    for (int i = 0; i < 6; ++i) glBindTextureUnit(static_cast<GLuint>(i), geo[i]->id());
    for (size_t l = 1; l < mLevels.size(); ++l) {
        const gl::Program& program = l == 1 ? mReduceFromPixels : mReduce;
        glUseProgram(program.id());
        glTextureBarrier(); // level l - 1 is complete before level l reads it
        glUniform1i(program.uniform("uLevel"), static_cast<int>(l));
        glViewport(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    timer.end();

    // The diagonal rule reads neighbours' discontinuity marks, so the flags follow the mipmap.
    timer.begin("refine_flags");
    if (mLevels.size() > 1) {
        glBindFramebuffer(GL_FRAMEBUFFER, mFlagsFbo.id());
        glUseProgram(mFlagsProgram.id());
        glBindTextureUnit(7, mDiscFlags.id());
        glViewport(mWidth, 0, mAtlasWidth - mWidth, mAtlasHeight); // the level column only
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    timer.end();

    timer.begin("stencil_setup");
    glBindFramebuffer(GL_FRAMEBUFFER, mIllumFbo.id());
    glViewport(0, 0, mAtlasWidth, mAtlasHeight);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mIllumFbo.id(), GL_COLOR, 0, zero);
    glClearNamedFramebufferfi(mIllumFbo.id(), GL_DEPTH_STENCIL, 0, 1.0f, 0);
    const GLuint zeroCounts[GIS_MAX_EYE_LEVELS] = {};
    mCounts.upload(0, sizeof zeroCounts, zeroCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, mCounts.id());
    glUseProgram(mReceivers.id());
    glBindTextureUnit(6, mFlags.id());
    bindPixels(in);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 1, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glBindVertexArray(mEmptyVao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_STENCIL_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    timer.end();
}

void EyeHierarchy::countReceivers(Counters& counters, int coveredPixels) {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(mCounts.id(), 0, sizeof mLastCounts, mLastCounts.data());
    double total = 0;
    for (size_t l = 0; l < mLevels.size(); ++l) {
        counters["receivers_l" + std::to_string(l)] = mLastCounts[l];
        total += mLastCounts[l];
    }
    counters["receivers_total"] = total;
    counters["eye_levels"] = static_cast<double>(mLevels.size());
    const double pixels = coveredPixels >= 0 ? coveredPixels : static_cast<double>(mWidth) * mHeight;
    counters["receiver_fraction"] = pixels > 0 ? total / pixels : 0.0;
}

void EyeHierarchy::reconstruct(const FrameInputs& in, const ParamSet& params, bool irradiance,
                               const gl::Framebuffer& indirectTarget, gl::PassTimer& timer) {
    bindUniforms();
    timer.begin("upsample");
    glBindVertexArray(mEmptyVao.id());
    glBindFramebuffer(GL_FRAMEBUFFER, mReconFbo.id());
    glUseProgram(mUpsample.id());
    glUniform1i(mUpsample.uniform("uInterpolate"), irradiance ? 1 : 0);
    glBindTextureUnit(0, mIllumination.id());
    glBindTextureUnit(1, mReconstructed.id());
    glBindTextureUnit(11, mGeoPosition.id()); // receiver geometry for the upsampling's edge weights
    glBindTextureUnit(12, mGeoNormal.id());
    for (int l = static_cast<int>(mLevels.size()) - 1; l >= 1; --l) {
        glTextureBarrier(); // level l + 1 is complete before level l reads it
        glUniform1i(mUpsample.uniform("uLevel"), l);
        glViewport(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, indirectTarget.id());
    glViewport(0, 0, in.width, in.height);
    glUseProgram(mResolve.id());
    glUniform1i(mResolve.uniform("uIrradiance"), irradiance ? 1 : 0);
    glUniform1i(mResolve.uniform("uInterpolate"), irradiance ? 1 : 0);
    glUniform1f(mResolve.uniform("uDetailAlpha"), static_cast<float>(params.getFloat("detail_alpha")));
    glBindTextureUnit(0, in.find("gbuffer.position")->id());
    glBindTextureUnit(1, in.find("gbuffer.normal")->id());
    glBindTextureUnit(2, in.find("gbuffer.albedo")->id());
    glBindTextureUnit(3, mReconstructed.id());
    glBindTextureUnit(4, mIllumination.id());
    glTextureBarrier();
    glDrawArrays(GL_TRIANGLES, 0, 3);
    timer.end();
}

std::vector<std::array<int, 3>> EyeHierarchy::readReceiverSet() const {
    std::vector<GLuint> packed(static_cast<size_t>(mAtlasWidth) * mAtlasHeight);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, mIllumFbo.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, mAtlasWidth, mAtlasHeight, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, packed.data());
    std::vector<std::array<int, 3>> set;
    for (int y = 0; y < mAtlasHeight; ++y)
        for (int x = 0; x < mAtlasWidth; ++x) {
            if ((packed[static_cast<size_t>(y) * mAtlasWidth + x] & 0xFFu) == 0) continue;
            for (size_t l = 0; l < mLevels.size(); ++l) {
                const EyeLevel& e = mLevels[l];
                if (x >= e.x && y >= e.y && x < e.x + e.width && y < e.y + e.height) {
                    set.push_back({static_cast<int>(l), x - e.x, y - e.y});
                    break;
                }
            }
        }
    std::sort(set.begin(), set.end());
    return set;
}

} // namespace gis

#include "gi/common/EyeHierarchy.h"

#include <algorithm>
#include <optional>

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

EyeInputHandles::EyeInputHandles(const gl::Program& p) {
    auto unit = [&](const char* name) {
        return p.declares(name) ? p.optionalTextureUnit(name) : gl::TextureUnit{gl::kNoUnit};
    };
    geoPosition = unit("uGeoPosition");
    geoNormal = unit("uGeoNormal");
    pixelPosition = unit("gPosition");
    pixelNormal = unit("gNormal");
    pixelAlbedo = unit("gAlbedo");
    atlasPosition = unit("uAtlasPosition");
    atlasNormal = unit("uAtlasNormal");
    atlasAlbedo = unit("uAtlasAlbedo");
}

EyeReceiverPassHandles::EyeReceiverPassHandles(const gl::Program& p)
    : inputs(p), list(p.storageBlock("EyeReceiverList")), illumination(p.imageUnit("uEyeIllumination")),
      groupBase(p.location("uEyeReceiverGroupBase")) {}

EyeHierarchy::ReduceProgram::ReduceProgram(gl::Program built)
    : program(std::move(built)), level(program.location("uLevel")),
      // Level 1 (GIS_FROM_GBUFFER) reads the G-buffer instead of the level below.
      geo{program.optionalTextureUnit("uGeoPosition"), program.optionalTextureUnit("uGeoNormal"),
          program.optionalTextureUnit("uGeoAlbedo"),   program.optionalTextureUnit("uDepthInfo"),
          program.optionalTextureUnit("uNormalMin"),   program.optionalTextureUnit("uNormalMax")},
      inputs(program) {}

EyeHierarchy::EyeHierarchy(EyeHierarchyOptions options) : mOptions(options) {
    // Every pass is a full-screen draw clipped by the viewport to one level: llvmpipe shades
    // fragments faster than it runs image load/store compute (the mipmap: 36 ms as compute, 23 ms
    // as fragments at 512^2).
    const auto build = [](const char* fragment,
                          const std::vector<std::pair<std::string, std::string>>& defines = {}) {
        return gl::Program::build(
            {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, fragment}}, defines);
    };
    const char* albedo = options.patchAlbedo ? "1" : "0";
    for (int metrics = 0; metrics < 2; ++metrics)
        mReduceFromPixels[static_cast<size_t>(metrics)] = std::make_unique<ReduceProgram>(
            build("gi/common/eye_mip_reduce.frag", {{"GIS_FROM_GBUFFER", "1"},
                                                    {"GIS_EYE_PIXEL_METRICS", metrics ? "1" : "0"},
                                                    {"GIS_EYE_ALBEDO", albedo}}));
    mReduce =
        std::make_unique<ReduceProgram>(build("gi/common/eye_mip_reduce.frag", {{"GIS_EYE_ALBEDO", albedo}}));

    mFlagsProgram.program = build("gi/common/eye_flags.frag");
    mFlagsProgram.level = mFlagsProgram.program.location("uLevel");
    mFlagsProgram.discFlags = mFlagsProgram.program.textureUnit("uDiscFlags");
    mFlagsProgram.flags = mFlagsProgram.program.textureUnit("uFlags");

    for (ReceiversProgram* r : {&mPixelReceivers, &mPatchReceivers}) {
        const bool pixels = r == &mPixelReceivers;
        r->program = build("gi/common/eye_receivers.frag",
                           {{"GIS_EYE_PIXEL_LEVEL", pixels ? "1" : "0"},
                            {"GIS_EYE_RECEIVER_LIST", options.receiverList ? "1" : "0"}});
        r->level = pixels ? r->program.optionalLocation("uLevel") : r->program.location("uLevel");
        r->flags = r->program.textureUnit("uFlags");
        r->inputs = EyeInputHandles(r->program);
        if (options.receiverList) r->list = r->program.storageBlock("EyeReceiverList");
    }
    if (options.receiverList) {
        mReceiverDispatch.program =
            gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/eye_receiver_dispatch.comp"}});
        mReceiverDispatch.list = mReceiverDispatch.program.storageBlock("EyeReceiverList");
    }

    UpsampleProgram& u = mUpsample;
    u.program = build("gi/common/eye_upsample.frag");
    u.interpolate = u.program.location("uInterpolate");
    u.level = u.program.location("uLevel");
    u.rendered = u.program.textureUnit("uRendered");
    u.reconstructed = u.program.textureUnit("uReconstructed");
    u.atlasPosition = u.program.textureUnit("uAtlasPosition");
    u.atlasNormal = u.program.textureUnit("uAtlasNormal");

    ResolveProgram& v = mResolve;
    v.program = build("gi/common/eye_resolve.frag");
    v.irradiance = v.program.location("uIrradiance");
    v.interpolate = v.program.location("uInterpolate");
    v.detailAlpha = v.program.location("uDetailAlpha");
    v.position = v.program.textureUnit("gPosition");
    v.normal = v.program.textureUnit("gNormal");
    v.albedo = v.program.textureUnit("gAlbedo");
    v.reconstructed = v.program.textureUnit("uReconstructed");
    v.rendered = v.program.textureUnit("uRendered");
    v.atlasPosition = v.program.optionalTextureUnit("uAtlasPosition");
    v.atlasNormal = v.program.optionalTextureUnit("uAtlasNormal");

    mEmptyVao = gl::VertexArray::create();
    mUbo = gl::Buffer::create(sizeof(shader::EyeHierarchyUniforms));
    for (gl::Query& query : mReceiverQueries) query = gl::Query::create(GL_SAMPLES_PASSED);
}

void EyeHierarchy::ensureLayout(int width, int height, int coarsestSize) {
    if (width == mWidth && height == mHeight && coarsestSize == mCoarsest) return;
    int atlasWidth = 0, atlasHeight = 0;
    std::vector<EyeLevel> levels = eyeLevelLayout(width, height, coarsestSize, &atlasWidth, &atlasHeight);
    // A layout used before takes its targets back: the frame budget's sizes recur, and allocating and
    // clearing eleven atlas textures cost a frame of a new size several milliseconds.
    mTargets = mRecentLayouts.exchange(
        {width, height, coarsestSize},
        mWidth > 0 ? std::optional<std::array<int, 3>>({mWidth, mHeight, mCoarsest}) : std::nullopt,
        std::move(mTargets), static_cast<double>(mAtlasWidth) * mAtlasHeight,
        [&] { return createTargets(atlasWidth, atlasHeight); });
    mLevels = std::move(levels);
    mAtlasWidth = atlasWidth;
    mAtlasHeight = atlasHeight;
    mWidth = width;
    mHeight = height;
    mCoarsest = coarsestSize;
}

EyeHierarchy::LayoutTargets EyeHierarchy::createTargets(int aw, int ah) const {
    LayoutTargets t;
    t.geoPosition = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    t.geoNormal = gl::Texture::create2D(GL_RGBA16F, aw, ah); // as precise as the G-buffer's normals
    t.geoAlbedo = gl::Texture::create2D(GL_RGBA16F, aw, ah);
    t.depthInfo = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    t.normalMin = gl::Texture::create2D(GL_RGBA16F, aw, ah);
    t.normalMax = gl::Texture::create2D(GL_RGBA16F, aw, ah);
    t.flags = gl::Texture::create2D(GL_R8UI, aw, ah);
    t.discFlags = gl::Texture::create2D(GL_R8UI, aw, ah);
    // The albedo last, so that a hierarchy without it attaches one target fewer.
    t.geoFbo = mOptions.patchAlbedo
                   ? gl::Framebuffer::of("eye hierarchy mipmaps",
                                         {&t.geoPosition, &t.geoNormal, &t.depthInfo, &t.normalMin,
                                          &t.normalMax, &t.discFlags, &t.geoAlbedo})
                   : gl::Framebuffer::of("eye hierarchy mipmaps", {&t.geoPosition, &t.geoNormal, &t.depthInfo,
                                                                   &t.normalMin, &t.normalMax, &t.discFlags});
    t.flagsFbo = gl::Framebuffer::of("eye refinement flags", {&t.flags});
    t.illumination = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    t.reconstructed = gl::Texture::create2D(GL_RGBA32F, aw, ah);
    t.stencil = gl::Texture::create2D(GL_DEPTH24_STENCIL8, aw, ah);
    t.illumFbo = gl::Framebuffer::of("multiresolution illumination buffer", {&t.illumination}, &t.stencil);
    t.reconFbo = gl::Framebuffer::of("reconstructed illumination", {&t.reconstructed});
    // The list packs a texel as y << 16 | x; GL's texture size limits keep an atlas far below that.
    GIS_ASSERT(aw < 65536 && ah < 65536);
    if (mOptions.receiverList)
        t.receiverList =
            gl::Buffer::create(sizeof(shader::EyeReceiverListHeader) +
                               sizeof(GLuint) * static_cast<size_t>(aw) * static_cast<size_t>(ah));
    // Padding texels must read as empty even before the first frame writes them (no pass writes
    // them, so targets taken back still hold the zeros).
    const float zero[4] = {0, 0, 0, 0};
    for (const gl::Texture* tex : {&t.geoPosition, &t.geoNormal, &t.geoAlbedo, &t.depthInfo, &t.normalMin,
                                   &t.normalMax, &t.illumination, &t.reconstructed})
        glClearTexImage(tex->id(), 0, GL_RGBA, GL_FLOAT, zero);
    const GLuint zeroU = 0;
    glClearTexImage(t.flags.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zeroU);
    glClearTexImage(t.discFlags.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zeroU);
    return t;
}

void EyeHierarchy::uploadUniforms(const ParamSet& params) {
    shader::EyeHierarchyUniforms u{};
    for (size_t l = 0; l < mLevels.size(); ++l)
        u.level[l] = glm::ivec4(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height);
    int options = 0;
    if (params.getBool("diagonal_refine")) options |= GIS_EYE_DIAGONAL;
    if (params.getEnum("depth_metric") == "derivative") options |= GIS_EYE_DEPTH_DERIVATIVE;
    if (params.getEnum("normal_metric") == "curvature") options |= GIS_EYE_CURVATURE;
    mPixelMetrics = (options & (GIS_EYE_DEPTH_DERIVATIVE | GIS_EYE_CURVATURE)) != 0;
    u.info = glm::ivec4(static_cast<int>(mLevels.size()), mWidth, mHeight, options);
    u.thresholds =
        glm::vec4(params.getFloat("depth_threshold"), params.getFloat("depth_derivative_threshold"),
                  params.getFloat("normal_threshold"), params.getFloat("curvature_threshold"));
    mUbo.upload(0, sizeof u, &u);
}

void EyeHierarchy::beginIlluminationPass(gl::Pass& pass, const EyeInputHandles& handles,
                                         const FrameInputs& in) const {
    pass.target(mTargets.illumFbo, mAtlasWidth, mAtlasHeight);
    bindInputs(pass, handles, in);
    pass.blend(GL_ONE, GL_ONE, GL_ONE, GL_ZERO); // rgb accumulates, alpha marks data
}

void EyeHierarchy::beginReceiverPass(gl::Pass& pass, const EyeReceiverPassHandles& handles,
                                     const FrameInputs& in) const {
    GIS_ASSERT(mOptions.receiverList);
    bindInputs(pass, handles.inputs, in);
    pass.buffer(handles.list, mTargets.receiverList)
        .image(handles.illumination, mTargets.illumination, GL_READ_WRITE, GL_RGBA32F);
}

unsigned EyeHierarchy::readReceiverCount() const {
    GIS_ASSERT(mOptions.receiverList);
    shader::EyeReceiverListHeader header{};
    glGetNamedBufferSubData(mTargets.receiverList.id(), 0, sizeof header, &header);
    const unsigned capacity = static_cast<unsigned>(
        (mTargets.receiverList.size() - static_cast<GLsizeiptr>(sizeof header)) / sizeof(unsigned));
    return std::min(header.counts.x, capacity);
}

void EyeHierarchy::clearIllumination() const {
    // The receiver passes' image stores before the clear.
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mTargets.illumFbo.id(), GL_COLOR, 0, zero);
}

bool EyeHierarchy::dispatchReceivers(gl::Pass& pass, const EyeReceiverPassHandles& handles,
                                     const std::function<bool()>& stop, int chunks) const {
    // The previous dispatch's image stores (and the stencil pass's list) before this one's loads.
    pass.barrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    if (!stop || chunks <= 1) {
        pass.set(handles.groupBase, 0u).dispatchIndirect(mTargets.receiverList);
        return true;
    }
    // Refinement: the count read back, then the list in chunks, `stop` asked between them.
    const unsigned receivers = readReceiverCount();
    const unsigned groups = (receivers + GIS_EYE_RECEIVER_GROUP - 1) / GIS_EYE_RECEIVER_GROUP;
    // One row of groups per chunk: a second row would run past the chunk into the next one.
    const auto parts = static_cast<unsigned>(chunks);
    const unsigned chunkGroups =
        std::clamp((groups + parts - 1) / parts, 1u, static_cast<unsigned>(GIS_EYE_RECEIVER_MAX_GROUPS_X));
    for (unsigned first = 0; first < groups; first += chunkGroups) {
        const unsigned count = std::min(chunkGroups, groups - first);
        if (first > 0) pass.barrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        pass.set(handles.groupBase, first).dispatch(static_cast<int>(count));
        if (first + count >= groups) break;
        if (stop()) return false;
    }
    return true;
}

void EyeHierarchy::bindInputs(gl::Pass& pass, const EyeInputHandles& h, const FrameInputs& in) const {
    pass.texture(h.geoPosition, mTargets.geoPosition)
        .texture(h.geoNormal, mTargets.geoNormal)
        .texture(h.atlasPosition, mTargets.geoPosition)
        .texture(h.atlasNormal, mTargets.geoNormal)
        .texture(h.atlasAlbedo, mTargets.geoAlbedo)
        .texture(h.pixelPosition, in.get("gbuffer.position"))
        .texture(h.pixelNormal, in.get("gbuffer.normal"))
        .texture(h.pixelAlbedo, in.get("gbuffer.albedo"));
}

void EyeHierarchy::bindUniforms() const {
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_EYE, mUbo.id());
}

void EyeHierarchy::buildGeometryLevels(const FrameInputs& in, gl::PassTimer& timer) {
    {
        gl::Pass pass(timer, "eye_mipmap");
        pass.target(mTargets.geoFbo, mAtlasWidth, mAtlasHeight);
        const gl::Texture* geo[6] = {&mTargets.geoPosition, &mTargets.geoNormal, &mTargets.geoAlbedo,
                                     &mTargets.depthInfo,   &mTargets.normalMin, &mTargets.normalMax};
        for (int i = 0; i < 6; ++i) pass.texture(mReduce->geo[static_cast<size_t>(i)], *geo[i]);
        const ReduceProgram& fromPixels = *mReduceFromPixels[mPixelMetrics ? 1 : 0];
        bindInputs(pass, fromPixels.inputs, in);
        for (size_t l = 1; l < mLevels.size(); ++l) {
            const ReduceProgram& program = l == 1 ? fromPixels : *mReduce;
            pass.use(program.program).textureBarrier(); // level l - 1 is complete before level l reads it
            pass.set(program.level, static_cast<int>(l))
                .viewport(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height)
                .drawFullscreen(mEmptyVao);
        }
    }

    // The diagonal rule reads neighbours' discontinuity marks, so the flags follow the mipmap.
    {
        gl::Pass pass(timer, "refine_flags");
        if (mLevels.size() > 1) {
            pass.target(mTargets.flagsFbo, mAtlasWidth, mAtlasHeight)
                .use(mFlagsProgram.program)
                .texture(mFlagsProgram.discFlags, mTargets.discFlags)
                .texture(mFlagsProgram.flags, mTargets.flags);
            // Coarsest first: each level reads its parents' finished flags. Padding keeps the cleared 0.
            for (size_t l = mLevels.size() - 1; l >= 1; --l) {
                pass.textureBarrier()
                    .set(mFlagsProgram.level, static_cast<int>(l))
                    .viewport(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height)
                    .drawFullscreen(mEmptyVao);
            }
        }
    }
}

void EyeHierarchy::build(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer) {
    const bool sameLayout =
        mWidth == in.width && mHeight == in.height && mCoarsest == params.getInt("coarsest_size");
    ensureLayout(in.width, in.height, params.getInt("coarsest_size"));
    uploadUniforms(params);
    bindUniforms();

    // A later VPL part of the same image: the G-buffer, so the mipmap and the refinement flags, are the
    // previous part's (the receivers' stencil below is reset with the illumination target each time).
    if (!(in.sameImageAsLastPart && sameLayout && mBuilt)) {
        buildGeometryLevels(in, timer);
        mBuilt = true;
        // Input may stop the frame here: the levels are whole (queued GL work runs to its end), and
        // the technique's own check after build() sees the same answer.
        if (in.interrupted()) return;
    }

    gl::Pass pass(timer, "stencil_setup");
    if (mOptions.receiverList) {
        const shader::EyeReceiverListHeader empty{};
        mTargets.receiverList.upload(0, sizeof empty, &empty);
    }
    pass.target(mTargets.illumFbo, mAtlasWidth, mAtlasHeight).clearColor(1).clearDepthStencil(1.0f, 0);
    pass.noColorWrites().stencilTest(true).stencilFunc(GL_ALWAYS, 1);
    // One draw per level, each counted: the padding between levels is never shaded.
    for (size_t l = 0; l < mLevels.size(); ++l) {
        const ReceiversProgram& r = l == 0 ? mPixelReceivers : mPatchReceivers;
        if (l <= 1) {
            pass.use(r.program).texture(r.flags, mTargets.flags);
            bindInputs(pass, r.inputs, in);
            if (mOptions.receiverList) pass.buffer(r.list, mTargets.receiverList);
        }
        pass.set(r.level, static_cast<int>(l))
            .viewport(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height)
            .drawFullscreenCounted(mEmptyVao, mReceiverQueries[l]);
    }
    if (mOptions.receiverList) {
        pass.barrier(GL_SHADER_STORAGE_BARRIER_BIT)
            .use(mReceiverDispatch.program)
            .buffer(mReceiverDispatch.list, mTargets.receiverList)
            .dispatch(1)
            .barrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    }
}

void EyeHierarchy::countReceivers(Counters& counters, int coveredPixels) {
    double total = 0;
    for (size_t l = 0; l < mLevels.size(); ++l) {
        GLuint passed = 0;
        glGetQueryObjectuiv(mReceiverQueries[l].id(), GL_QUERY_RESULT, &passed);
        mLastCounts[l] = passed;
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
    gl::Pass pass(timer, "upsample");
    pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT); // a receiver pass's image stores before the fetches
    const UpsampleProgram& u = mUpsample;
    pass.target(mTargets.reconFbo, mAtlasWidth, mAtlasHeight)
        .use(u.program)
        .set(u.interpolate, irradiance ? 1 : 0);
    pass.texture(u.rendered, mTargets.illumination)
        .texture(u.reconstructed, mTargets.reconstructed)
        .texture(u.atlasPosition, mTargets.geoPosition) // receiver geometry for the upsampling's edge weights
        .texture(u.atlasNormal, mTargets.geoNormal);
    for (int l = static_cast<int>(mLevels.size()) - 1; l >= 1; --l) {
        pass.textureBarrier(); // level l + 1 is complete before level l reads it
        pass.set(u.level, l)
            .viewport(mLevels[l].x, mLevels[l].y, mLevels[l].width, mLevels[l].height)
            .drawFullscreen(mEmptyVao);
    }
    const ResolveProgram& v = mResolve;
    pass.target(indirectTarget, in.width, in.height).use(v.program);
    pass.set(v.irradiance, irradiance ? 1 : 0)
        .set(v.interpolate, irradiance ? 1 : 0)
        .set(v.detailAlpha, static_cast<float>(params.getFloat("detail_alpha")));
    pass.texture(v.position, in.get("gbuffer.position"))
        .texture(v.normal, in.get("gbuffer.normal"))
        .texture(v.albedo, in.get("gbuffer.albedo"))
        .texture(v.reconstructed, mTargets.reconstructed)
        .texture(v.rendered, mTargets.illumination)
        .texture(v.atlasPosition, mTargets.geoPosition)
        .texture(v.atlasNormal, mTargets.geoNormal);
    pass.textureBarrier().drawFullscreen(mEmptyVao);
}

namespace {
// The (level, x within the level) of atlas texel (x, y), or level -1 for padding.
std::array<int, 3> levelTexel(const std::vector<EyeLevel>& levels, int x, int y) {
    for (size_t l = 0; l < levels.size(); ++l) {
        const EyeLevel& e = levels[l];
        if (x >= e.x && y >= e.y && x < e.x + e.width && y < e.y + e.height)
            return {static_cast<int>(l), x - e.x, y - e.y};
    }
    return {-1, x, y};
}
} // namespace

long EyeHierarchy::listedReceivers() const {
    GIS_ASSERT(mOptions.receiverList);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    shader::EyeReceiverListHeader h{};
    glGetNamedBufferSubData(mTargets.receiverList.id(), 0, sizeof h, &h);
    return static_cast<long>(h.counts.x);
}

bool EyeHierarchy::capVplsToReceivers(const FrameInputs& in, const TechniqueInfo& info, ParamSet& params,
                                      const std::function<long(const ParamSet&)>& vpls,
                                      Counters& counters) const {
    if (!params.has("receiver_share_cap") || !(params.getFloat("receiver_share_cap") < 1.0)) return false;
    if (capVplsForReceivers(info, params, vpls(params), static_cast<double>(in.width) * in.height,
                            static_cast<double>(listedReceivers()), in.receiverCapExponent) == 0)
        return false;
    counters["receiver_share_capped_vpls"] = static_cast<double>(vpls(params));
    return true;
}

std::vector<std::array<int, 3>> EyeHierarchy::readReceiverList(shader::EyeReceiverListHeader* header) const {
    GIS_ASSERT(mOptions.receiverList);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    shader::EyeReceiverListHeader h{};
    glGetNamedBufferSubData(mTargets.receiverList.id(), 0, sizeof h, &h);
    if (header) *header = h;
    const size_t capacity = (static_cast<size_t>(mTargets.receiverList.size()) - sizeof h) / sizeof(GLuint);
    std::vector<GLuint> items(std::min<size_t>(h.counts.x, capacity));
    if (!items.empty())
        glGetNamedBufferSubData(mTargets.receiverList.id(), sizeof h,
                                static_cast<GLsizeiptr>(items.size() * sizeof(GLuint)), items.data());
    std::vector<std::array<int, 3>> list;
    for (GLuint item : items)
        list.push_back(levelTexel(mLevels, static_cast<int>(item & 0xFFFFu), static_cast<int>(item >> 16)));
    std::sort(list.begin(), list.end());
    return list;
}

std::vector<std::array<int, 3>> EyeHierarchy::readReceiverSet() const {
    std::vector<GLuint> packed(static_cast<size_t>(mAtlasWidth) * mAtlasHeight);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, mTargets.illumFbo.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, mAtlasWidth, mAtlasHeight, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, packed.data());
    std::vector<std::array<int, 3>> set;
    for (int y = 0; y < mAtlasHeight; ++y)
        for (int x = 0; x < mAtlasWidth; ++x) {
            if ((packed[static_cast<size_t>(y) * mAtlasWidth + x] & 0xFFu) == 0) continue;
            const std::array<int, 3> texel = levelTexel(mLevels, x, y);
            if (texel[0] >= 0) set.push_back(texel);
        }
    std::sort(set.begin(), set.end());
    return set;
}

} // namespace gis

#include "gi/multires_splat/MultiresSplat.h"

#include <algorithm>

#include "core/Log.h"
#include "gl/ShaderShared.h"

namespace gis {

MultiresSplat::MultiresSplat() {
    mSeed = gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_splat/seed.comp"}});
    mRefine = gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_splat/refine.comp"}});
    mAdvance = gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_splat/advance.comp"}});
    mSplat = KernelPrograms({{GL_VERTEX_SHADER, "gi/multires_splat/splat.vert"},
                             {GL_FRAGMENT_SHADER, "gi/multires_splat/splat.frag"}});
    mCounters = gl::Buffer::create(sizeof(shader::SubsplatCounters), nullptr,
                                   GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    mRefineTf = gl::Program::build({{GL_VERTEX_SHADER, "gi/multires_splat/refine_tf.vert"},
                                    {GL_GEOMETRY_SHADER, "gi/multires_splat/refine_tf.geom"}},
                                   {}, {"gNext", "gl_NextBuffer", "gSplat"});
    const std::vector<gl::ShaderStage> tfSplat = {{GL_VERTEX_SHADER, "gi/multires_splat/splat.vert"},
                                                  {GL_FRAGMENT_SHADER, "gi/multires_splat/splat.frag"}};
    mSplatTf = KernelPrograms(tfSplat, {{"GIS_ITEM_ATTRIBUTE", "1"}});
    mItemVao = gl::VertexArray::create();
    glEnableVertexArrayAttrib(mItemVao.id(), 0);
    glVertexArrayAttribIFormat(mItemVao.id(), 0, 2, GL_UNSIGNED_INT, 0);
    glVertexArrayAttribBinding(mItemVao.id(), 0, 0);
}

void MultiresSplat::ensureFeedbackLists() {
    const auto& levels = mEye.levels();
    const bool same =
        levels.size() == mTfLevels.size() &&
        std::equal(levels.begin(), levels.end(), mTfLevels.begin(), [](const EyeLevel& a, const EyeLevel& b) {
            return a.width == b.width && a.height == b.height;
        });
    if (same) return;
    mTfLevels = levels;
    const size_t n = levels.size();
    mTfo.clear();
    mTfNext.clear();
    mTfSplat.clear();
    mTfWritten.clear();
    const auto itemBytes = [](const EyeLevel& l) {
        return static_cast<GLsizeiptr>(std::max(l.width * l.height, 1)) * 2 *
               static_cast<GLsizeiptr>(sizeof(GLuint));
    };
    for (size_t l = 0; l < n; ++l) {
        // A level's splat list holds at most its texels; the next list at most the level below's.
        mTfSplat.push_back(gl::Buffer::create(itemBytes(levels[l]), nullptr, GL_MAP_READ_BIT));
        mTfNext.push_back(gl::Buffer::create(itemBytes(l > 0 ? levels[l - 1] : levels[0]), nullptr, 0));
        mTfo.push_back(gl::TransformFeedback::create());
        glTransformFeedbackBufferBase(mTfo.back().id(), 0, mTfNext.back().id());
        glTransformFeedbackBufferBase(mTfo.back().id(), 1, mTfSplat.back().id());
        mTfWritten.push_back(gl::Query::create(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN));
    }
    const EyeLevel& c = levels.back();
    std::vector<GLuint> seed;
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            seed.push_back(0);
            seed.push_back((static_cast<GLuint>(n - 1) << 28) | (static_cast<GLuint>(y) << 14) |
                           static_cast<GLuint>(x));
        }
    mTfSeed = gl::Buffer::create(static_cast<GLsizeiptr>(seed.size() * sizeof(GLuint)), seed.data(), 0);
    mTfSeedCount = static_cast<GLsizei>(seed.size() / 2);
}

void MultiresSplat::refineWithFeedback(const FrameInputs& in, Counters& counters) {
    ensureFeedbackLists();
    const int levels = static_cast<int>(mTfLevels.size());
    glEnable(GL_RASTERIZER_DISCARD);
    glUseProgram(mRefineTf.id());
    glBindTextureUnit(6, mEye.flags().id());
    mEye.bindPixels(in);
    glBindVertexArray(mItemVao.id());
    for (int level = levels - 1; level >= 0; --level) {
        glUniform1i(mRefineTf.uniform("uLevel"), level);
        glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, mTfo[level].id());
        glBeginQueryIndexed(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, 1, mTfWritten[level].id());
        glBeginTransformFeedback(GL_POINTS);
        if (level == levels - 1) {
            glVertexArrayVertexBuffer(mItemVao.id(), 0, mTfSeed.id(), 0, 2 * sizeof(GLuint));
            glDrawArrays(GL_POINTS, 0, mTfSeedCount);
        } else {
            glVertexArrayVertexBuffer(mItemVao.id(), 0, mTfNext[level + 1].id(), 0, 2 * sizeof(GLuint));
            glDrawTransformFeedbackStream(GL_POINTS, mTfo[level + 1].id(), 0);
        }
        glEndTransformFeedback();
        glEndQueryIndexed(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, 1);
    }
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
    glDisable(GL_RASTERIZER_DISCARD);
    (void)counters;
}

void MultiresSplat::splatFeedbackLists(int vplCount) {
    // glDrawTransformFeedbackStreamInstanced(..., stream 1, ...) drew nothing on Mesa 22.3's llvmpipe
    // (stream 0 draws work), so the splat lists are drawn with the counts from the queries: a CPU
    // wait for the refinement that the compute lists avoid.
    mTfCounts.assign(mTfLevels.size(), 0);
    for (size_t level = 0; level < mTfLevels.size(); ++level) {
        glGetQueryObjectuiv(mTfWritten[level].id(), GL_QUERY_RESULT, &mTfCounts[level]);
        if (mTfCounts[level] == 0) continue;
        glVertexArrayVertexBuffer(mItemVao.id(), 0, mTfSplat[level].id(), 0, 2 * sizeof(GLuint));
        glDrawArraysInstanced(GL_POINTS, 0, static_cast<GLsizei>(mTfCounts[level]), vplCount);
    }
}

void MultiresSplat::resize(int width, int height) {
    mIndirect.resize(width, height, "multires_splat indirect");
}

void MultiresSplat::ensureCapacity(GLuint items) {
    if (items == mCapacity) return;
    const GLsizeiptr bytes = static_cast<GLsizeiptr>(items) * 2 * sizeof(GLuint);
    mListA = gl::Buffer::create(bytes, nullptr, 0);
    mListB = gl::Buffer::create(bytes, nullptr, 0);
    mSplatList = gl::Buffer::create(bytes, nullptr, GL_MAP_READ_BIT);
    mCapacity = items;
}

bool MultiresSplat::glossyTransport(const ParamSet& params) const {
    // Built once: info() assembles the whole parameter table, and this runs every frame.
    static const TechniqueInfo kInfo = multiresSplatInfo();
    return kInfo.glossyTransport(params);
}

void MultiresSplat::bindGlossy(const gl::Program& program, const FrameInputs& in, bool perVpl) const {
    const bool glossy = perVpl && in.glossy && in.find("gbuffer.specular") != nullptr;
    glUniform1i(program.uniform("uGlossy"), glossy ? 1 : 0);
    glUniform1f(program.uniform("uGlossyMinRoughness"), in.glossyMinRoughness);
    if (!glossy) return;
    glBindTextureUnit(14, in.find("gbuffer.specular")->id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, mVpls.glossyBuffer().id());
}

void MultiresSplat::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                            Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mEye.build(in, params, timer);
    const bool perVpl = params.getEnum("refinement") == "illumination";
    // A once-per-frame list holds each texel at most once: no need for the per-VPL capacity.
    long long texels = 0;
    for (const EyeLevel& l : mEye.levels()) texels += static_cast<long long>(l.width) * l.height;
    const long long cap = params.getInt("max_subsplats");
    ensureCapacity(static_cast<GLuint>(perVpl ? cap : std::min(cap, texels)));
    const bool feedback = !perVpl && params.getEnum("list_builder") == "transform_feedback";
    mLastFeedback = feedback;
    const int levels = static_cast<int>(mEye.levels().size());
    const EyeLevel& coarsest = mEye.levels().back();

    timer.begin("subsplat_refine");
    shader::SubsplatCounters zero{};
    long long seedWanted = 0;
    if (vplCount > 0 && !feedback) {
        seedWanted = static_cast<long long>(coarsest.width) * coarsest.height * (perVpl ? vplCount : 1);
        // Seed items beyond the int range the seed pass indexes are dropped and reported like the
        // list cap's (counts.w), never silently.
        zero.counts.w =
            static_cast<GLuint>(std::min<long long>(std::max(seedWanted - (1LL << 30), 0LL), ~0u));
    }
    mCounters.upload(0, sizeof zero, &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, mCounters.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mVpls.buffer().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, mSplatList.id());
    glBindTextureUnit(6, mEye.flags().id());
    mEye.bindPixels(in);
    glBindTextureUnit(11, mEye.geoPosition().id());
    glBindTextureUnit(12, mEye.geoNormal().id());
    glBindTextureUnit(13, mEye.geoAlbedo().id());
    if (vplCount > 0 && feedback) {
        refineWithFeedback(in, counters);
    } else if (vplCount > 0) {
        const int seedItems = static_cast<int>(std::min<long long>(seedWanted, 1 << 30));
        // The seed fills the "next" list; each level then advances (next -> input, indirect
        // dispatch size) and refines.
        const gl::Buffer* current = &mListB;
        const gl::Buffer* next = &mListA;
        glUseProgram(mSeed.id());
        glUniform1i(mSeed.uniform("uItems"), seedItems);
        glUniform1ui(mSeed.uniform("uCapacity"), mCapacity);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, next->id());
        // 2D: coarsest texels x VPLs / 64 exceeds GL_MAX_COMPUTE_WORK_GROUP_COUNT's guaranteed 65535 in
        // one dimension at 128^2 VPLs (GL_INVALID_VALUE and no light before this was split).
        const GLuint groups = static_cast<GLuint>((seedItems + GIS_SUBSPLAT_GROUP - 1) / GIS_SUBSPLAT_GROUP);
        const GLuint groupsX = std::min<GLuint>(groups, GIS_SUBSPLAT_MAX_GROUPS_X);
        glDispatchCompute(groupsX, groupsX > 0 ? (groups + groupsX - 1) / groupsX : 1, 1);

        glUseProgram(mRefine.id());
        glUniform1ui(mRefine.uniform("uCapacity"), mCapacity);
        glUniform1f(mRefine.uniform("uIllumThreshold"),
                    static_cast<float>(params.getFloat("illum_threshold")));
        glUniform1i(mRefine.uniform("uPerVpl"), perVpl ? 1 : 0);
        glUniform1f(mRefine.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        setVplClamp(mRefine, params);
        glUniform1f(mRefine.uniform("uPhongKs"), static_cast<float>(params.getFloat("phong_ks")));
        glUniform1f(mRefine.uniform("uPhongExponent"), static_cast<float>(params.getFloat("phong_exponent")));
        bindGlossy(mRefine, in, perVpl);
        glUseProgram(mAdvance.id());
        glUniform1i(mAdvance.uniform("uMode"), 0);
        glUniform1ui(mAdvance.uniform("uCapacity"), mCapacity);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, mCounters.id());
        for (int level = levels - 1; level >= 0; --level) {
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            glUseProgram(mAdvance.id());
            glDispatchCompute(1, 1, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
            std::swap(current, next);
            glUseProgram(mRefine.id());
            glUniform1i(mRefine.uniform("uLevel"), level);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, current->id());
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, next->id());
            glDispatchComputeIndirect(0);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        glUseProgram(mAdvance.id());
        glUniform1i(mAdvance.uniform("uMode"), 1);
        glUniform1ui(mAdvance.uniform("uCapacity"), mCapacity);
        glUniform1ui(mAdvance.uniform("uInstances"), perVpl ? 1u : static_cast<GLuint>(vplCount));
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    }
    timer.end();

    timer.begin("subsplat_splat");
    if (vplCount > 0) {
        const gl::Program& splat = (feedback ? mSplatTf : mSplat).get(vplKernel(params));
        glUseProgram(splat.id());
        glUniform2i(splat.uniform("uAtlasSize"), mEye.atlasWidth(), mEye.atlasHeight());
        glUniform1i(splat.uniform("uPerVpl"), perVpl ? 1 : 0);
        glUniform1f(splat.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        setVplClamp(splat, params);
        glUniform1f(splat.uniform("uPhongKs"), static_cast<float>(params.getFloat("phong_ks")));
        glUniform1f(splat.uniform("uPhongExponent"), static_cast<float>(params.getFloat("phong_exponent")));
        bindGlossy(splat, in, perVpl);
        mEye.beginIlluminationPass(in, false); // every list item is a receiver: no stencil
        if (feedback) {
            glBindVertexArray(mItemVao.id());
            splatFeedbackLists(vplCount);
        } else {
            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, mCounters.id());
            glDrawArraysIndirect(GL_POINTS,
                                 reinterpret_cast<const void*>(offsetof(shader::SubsplatCounters, draw)));
            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
        }
        mEye.endIlluminationPass();
    }
    timer.end();

    mEye.reconstruct(in, params, !perVpl, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);

    shader::SubsplatCounters c{};
    if (feedback) {
        if (vplCount == 0) mTfCounts.assign(mTfLevels.size(), 0);
        for (size_t l = 0; l < mTfCounts.size(); ++l) c.perLevel[l / 4][l % 4] = mTfCounts[l];
    } else {
        glGetNamedBufferSubData(mCounters.id(), 0, sizeof c, &c);
    }
    double total = 0;
    for (int l = 0; l < levels; ++l) {
        const double n = c.perLevel[l / 4][l % 4];
        counters["subsplats_l" + std::to_string(l)] = n;
        total += n;
    }
    counters["subsplats_total"] = total;
    counters["subsplat_capped"] = c.counts.w;
    if (perVpl && vplCount > 0) counters["subsplats_per_vpl"] = total / vplCount;
    counters["splat_points"] = perVpl ? total : total * vplCount;
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

std::vector<std::array<int, 3>> MultiresSplat::readSplatPatches() const {
    std::vector<GLuint> items;
    if (mLastFeedback) {
        for (size_t l = 0; l < mTfCounts.size(); ++l) {
            std::vector<GLuint> level(static_cast<size_t>(mTfCounts[l]) * 2);
            if (!level.empty())
                glGetNamedBufferSubData(mTfSplat[l].id(), 0,
                                        static_cast<GLsizeiptr>(level.size() * sizeof(GLuint)), level.data());
            items.insert(items.end(), level.begin(), level.end());
        }
    }
    if (!mLastFeedback) {
        shader::SubsplatCounters c{};
        glGetNamedBufferSubData(mCounters.id(), 0, sizeof c, &c);
        items.resize(static_cast<size_t>(std::min(c.counts.z, mCapacity)) * 2);
        if (!items.empty())
            glGetNamedBufferSubData(mSplatList.id(), 0,
                                    static_cast<GLsizeiptr>(items.size() * sizeof(GLuint)), items.data());
    }
    const GLuint n = static_cast<GLuint>(items.size() / 2);
    std::vector<std::array<int, 3>> set;
    set.reserve(n);
    for (GLuint i = 0; i < n; ++i) {
        const GLuint packed = items[2 * i + 1];
        set.push_back({static_cast<int>(packed >> 28), static_cast<int>(packed & 0x3FFFu),
                       static_cast<int>((packed >> 14) & 0x3FFFu)});
    }
    std::sort(set.begin(), set.end());
    return set;
}

} // namespace gis

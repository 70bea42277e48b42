#include "gi/multires_splat/MultiresSplat.h"

#include <algorithm>

#include "gi/common/ParamSpecs.h"
#include "core/Log.h"
#include "gl/ShaderShared.h"

namespace gis {

MultiresSplat::ShadingHandles::ShadingHandles(const gl::Program& p)
    : perVpl(p.location("uPerVpl")), minDistance(p.optionalLocation("uMinDistance")),
      phongKs(p.optionalLocation("uPhongKs")), phongExponent(p.optionalLocation("uPhongExponent")),
      patchSpecular(p.optionalTextureUnit("uPatchSpecular")), vpls(p.storageBlock("VplBuffer")), transport(p),
      eye(p) {}

MultiresSplat::SplatProgram::SplatProgram(gl::Program built)
    : program(std::move(built)), atlasSize(program.location("uAtlasSize")),
      splatList(program.optionalStorageBlock("SplatList")), shading(program) {}

MultiresSplat::RefineProgram::RefineProgram(gl::Program built)
    : program(std::move(built)), level(program.location("uLevel")), capacity(program.location("uCapacity")),
      illumThreshold(program.location("uIllumThreshold")), flags(program.textureUnit("uFlags")),
      inList(program.storageBlock("InList")), nextList(program.storageBlock("NextList")),
      splatList(program.storageBlock("SplatList")), counters(program.storageBlock("Counters")),
      shading(program) {}

MultiresSplat::MultiresSplat() {
    SeedProgram& seed = mSeed;
    seed.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_splat/seed.comp"}});
    seed.items = seed.program.location("uItems");
    seed.capacity = seed.program.location("uCapacity");
    seed.flags = seed.program.textureUnit("uFlags");
    seed.nextList = seed.program.storageBlock("NextList");
    seed.counters = seed.program.storageBlock("Counters");
    seed.eye = EyeInputHandles(seed.program);
    mRefine = std::make_unique<RefineProgram>(
        gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_splat/refine.comp"}}));
    AdvanceProgram& advance = mAdvance;
    advance.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_splat/advance.comp"}});
    advance.mode = advance.program.location("uMode");
    advance.capacity = advance.program.location("uCapacity");
    advance.instances = advance.program.location("uInstances");
    advance.counters = advance.program.storageBlock("Counters");
    const std::vector<gl::ShaderStage> splat = {{GL_VERTEX_SHADER, "gi/multires_splat/splat.vert"},
                                                {GL_FRAGMENT_SHADER, "gi/multires_splat/splat.frag"}};
    mSplat = KernelPrograms<SplatProgram>(splat);
    mCounters = gl::Buffer::create(sizeof(shader::SubsplatCounters), nullptr,
                                   GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    RefineTfProgram& tf = mRefineTf;
    tf.program = gl::Program::build({{GL_VERTEX_SHADER, "gi/multires_splat/refine_tf.vert"},
                                     {GL_GEOMETRY_SHADER, "gi/multires_splat/refine_tf.geom"}},
                                    {}, {"gNext", "gl_NextBuffer", "gSplat"});
    tf.level = tf.program.location("uLevel");
    tf.flags = tf.program.textureUnit("uFlags");
    tf.eye = EyeInputHandles(tf.program);
    mSplatTf = KernelPrograms<SplatProgram>(splat, {{"GIS_ITEM_ATTRIBUTE", "1"}});
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

void MultiresSplat::refineWithFeedback(gl::Pass& pass, const FrameInputs& in) {
    ensureFeedbackLists();
    const int levels = static_cast<int>(mTfLevels.size());
    glEnable(GL_RASTERIZER_DISCARD);
    pass.use(mRefineTf.program).texture(mRefineTf.flags, mEye.flags());
    mEye.bindInputs(pass, mRefineTf.eye, in);
    glBindVertexArray(mItemVao.id());
    for (int level = levels - 1; level >= 0; --level) {
        pass.set(mRefineTf.level, level);
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

void MultiresSplat::setShading(gl::Pass& pass, const ShadingHandles& h, const FrameInputs& in,
                               const ParamSet& params, bool perVpl) const {
    pass.set(h.perVpl, perVpl ? 1 : 0)
        .set(h.minDistance, vplMinDistance(params, in.sceneSize))
        .set(h.phongKs, static_cast<float>(params.getFloat("phong_ks")))
        .set(h.phongExponent, static_cast<float>(params.getFloat("phong_exponent")));
    const bool glossy = perVpl && in.glossy && in.find("gbuffer.specular") != nullptr;
    h.transport.set(pass, params, in.sceneSize, glossy, in.glossyMinRoughness, &mVpls.glossyBuffer());
    if (glossy) pass.texture(h.patchSpecular, in.get("gbuffer.specular"));
}

void MultiresSplat::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                            Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mEye.build(in, params, timer);
    // The eye hierarchy is whole (a later part of the same image keeps it): input may stop the frame.
    if (in.interrupted()) return;
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

    {
        gl::Pass pass(timer, "subsplat_refine");
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
        const RefineProgram& r = *mRefine;
        pass.buffer(r.counters, mCounters)
            .buffer(r.shading.vpls, mVpls.buffer())
            .buffer(r.splatList, mSplatList);
        if (vplCount > 0 && feedback) {
            refineWithFeedback(pass, in);
        } else if (vplCount > 0) {
            const int seedItems = static_cast<int>(std::min<long long>(seedWanted, 1 << 30));
            // The seed fills the "next" list; each level then advances (next -> input, indirect
            // dispatch size) and refines.
            const gl::Buffer* current = &mListB;
            const gl::Buffer* next = &mListA;
            pass.use(mSeed.program).set(mSeed.items, seedItems).set(mSeed.capacity, mCapacity);
            pass.texture(mSeed.flags, mEye.flags()).buffer(mSeed.nextList, *next);
            mEye.bindInputs(pass, mSeed.eye, in);
            // 2D: coarsest texels x VPLs / 64 exceeds GL_MAX_COMPUTE_WORK_GROUP_COUNT's guaranteed 65535 in
            // one dimension at 128^2 VPLs (GL_INVALID_VALUE and no light before this was split).
            const int groups = (seedItems + GIS_SUBSPLAT_GROUP - 1) / GIS_SUBSPLAT_GROUP;
            const int groupsX = std::min(groups, static_cast<int>(GIS_SUBSPLAT_MAX_GROUPS_X));
            pass.dispatch(groupsX, groupsX > 0 ? (groups + groupsX - 1) / groupsX : 1);

            pass.use(r.program)
                .set(r.capacity, mCapacity)
                .set(r.illumThreshold, static_cast<float>(params.getFloat("illum_threshold")))
                .texture(r.flags, mEye.flags());
            setShading(pass, r.shading, in, params, perVpl);
            mEye.bindInputs(pass, r.shading.eye, in);
            pass.use(mAdvance.program).set(mAdvance.mode, 0).set(mAdvance.capacity, mCapacity);
            for (int level = levels - 1; level >= 0; --level) {
                pass.barrier(GL_SHADER_STORAGE_BARRIER_BIT);
                pass.use(mAdvance.program)
                    .dispatch(1)
                    .barrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
                std::swap(current, next);
                pass.use(r.program).set(r.level, level).buffer(r.inList, *current).buffer(r.nextList, *next);
                pass.dispatchIndirect(mCounters);
            }
            pass.barrier(GL_SHADER_STORAGE_BARRIER_BIT);
            pass.use(mAdvance.program)
                .set(mAdvance.mode, 1)
                .set(mAdvance.capacity, mCapacity)
                .set(mAdvance.instances, perVpl ? 1u : static_cast<GLuint>(vplCount))
                .dispatch(1)
                .barrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
        }
    }

    {
        gl::Pass pass(timer, "subsplat_splat");
        if (vplCount > 0) {
            const SplatProgram& splat = (feedback ? mSplatTf : mSplat).get(vplKernel(params));
            pass.use(splat.program).set(splat.atlasSize, glm::ivec2(mEye.atlasWidth(), mEye.atlasHeight()));
            setShading(pass, splat.shading, in, params, perVpl);
            pass.buffer(splat.shading.vpls, mVpls.buffer()).buffer(splat.splatList, mSplatList);
            mEye.beginIlluminationPass(pass, splat.shading.eye, in); // every list item is a receiver
            if (feedback) {
                glBindVertexArray(mItemVao.id());
                splatFeedbackLists(vplCount);
            } else {
                glBindBuffer(GL_DRAW_INDIRECT_BUFFER, mCounters.id());
                glDrawArraysIndirect(GL_POINTS,
                                     reinterpret_cast<const void*>(offsetof(shader::SubsplatCounters, draw)));
                glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
            }
        }
    }

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

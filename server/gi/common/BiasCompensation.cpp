#include "gi/common/BiasCompensation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/glm.hpp>

#include "gi/common/ParamSpecs.h"
#include "gl/ShaderShared.h"

namespace gis {
namespace {

constexpr int kGroup = 8;          // GIS_SSBC_GROUP in ssbc_common.glsl
constexpr int kMaxVisited = 16384; // per pixel and step: bounds the frame time for tiny b
constexpr double kDegToRad = 3.14159265358979 / 180.0;

int groupsFor(int n) {
    return (n + kGroup - 1) / kGroup;
}

} // namespace

BiasCompensation::BiasCompensation() {
    BaseProgram& base = mBase;
    base.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_base.comp"}});
    const gl::Program& b = base.program;
    base.tanHalfFov = b.location("uTanHalfFov");
    base.forward = b.location("uForward");
    base.cosGrazing = b.location("uCosGrazing");
    base.withIndirect = b.location("uWithIndirect");
    base.position = b.textureUnit("gPosition");
    base.normal = b.textureUnit("gNormal");
    base.direct = b.textureUnit("uDirect");
    base.indirect = b.textureUnit("uIndirect");
    base.geoOut = b.imageUnit("uGeoOut");
    base.normalOut = b.imageUnit("uNormalOut");
    base.illumOut = b.imageUnit("uIllumOut");
    base.sums = b.optionalStorageBlock("SsbcSums");

    ReduceProgram& reduce = mReduce;
    reduce.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_reduce.comp"}});
    const gl::Program& r = reduce.program;
    reduce.level = r.optionalLocation("uLevel");
    reduce.mode = r.location("uMode");
    reduce.outSize = r.location("uOutSize");
    reduce.childReal = r.location("uChildReal");
    reduce.geoIn = r.imageUnit("uGeoIn");
    reduce.geoOut = r.imageUnit("uGeoOut");
    reduce.normalIn = r.imageUnit("uNormalIn");
    reduce.normalOut = r.imageUnit("uNormalOut");
    reduce.illumIn = r.imageUnit("uIllumIn");
    reduce.illumOut = r.imageUnit("uIllumOut");

    IntegrateProgram& integrate = mIntegrate;
    integrate.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_integrate.comp"}});
    const gl::Program& i = integrate.program;
    integrate.b = i.location("uB");
    integrate.r = i.location("uR");
    integrate.tanHalfFov = i.location("uTanHalfFov");
    integrate.levels = i.location("uLevels");
    integrate.solidAngle = i.location("uSolidAngle");
    integrate.discAngle = i.location("uDiscAngle");
    integrate.maxVisited = i.location("uMaxVisited");
    integrate.slot = i.location("uSlot");
    integrate.receiverLevel = i.location("uReceiverLevel");
    integrate.geo = i.textureUnit("uGeo");
    integrate.normal = i.textureUnit("uNormal");
    integrate.illum = i.textureUnit("uIllum");
    integrate.albedo = i.textureUnit("gAlbedo");
    integrate.indirect = i.imageUnit("uIndirect");
    integrate.nextIllum = i.imageUnit("uNextIllum");
    integrate.halfOut = i.imageUnit("uHalfOut");
    integrate.sums = i.optionalStorageBlock("SsbcSums");

    UpsampleProgram& upsample = mUpsample;
    upsample.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_upsample.comp"}});
    const gl::Program& u = upsample.program;
    upsample.slot = u.location("uSlot");
    upsample.geo = u.textureUnit("uGeo");
    upsample.normal = u.textureUnit("uNormal");
    upsample.half = u.textureUnit("uHalf");
    upsample.albedo = u.textureUnit("gAlbedo");
    upsample.target = u.imageUnit("uTarget");
    upsample.nextIllum = u.imageUnit("uNextIllum");
    upsample.sums = u.optionalStorageBlock("SsbcSums");

    BlurProgram& blur = mBlur;
    blur.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_blur.comp"}});
    blur.pass = blur.program.location("uPass");
    blur.geo = blur.program.textureUnit("uGeo");
    blur.normal = blur.program.textureUnit("uNormal");
    blur.source = blur.program.textureUnit("uSource");
    blur.out = blur.program.imageUnit("uOut");
    blur.sums = blur.program.optionalStorageBlock("SsbcSums");
}

void BiasCompensation::ensure(int width, int height, int levels) {
    if (width == mWidth && height == mHeight && levels == mLevels) return;
    const int align = 1 << (levels - 1);
    mPadW = (width + align - 1) / align * align;
    mPadH = (height + align - 1) / align * align;
    mGeo = gl::Texture::create2D(GL_RGBA32F, mPadW, mPadH, levels);
    mNormal = gl::Texture::create2D(GL_RGBA32F, mPadW, mPadH, levels);
    for (auto& t : mIllum) t = gl::Texture::create2D(GL_RGBA32F, mPadW, mPadH, levels);
    const GLsizeiptr slots = kMaxIterations + 1;
    mSums = gl::Buffer::create(slots * groupsFor(mPadW) * groupsFor(mPadH) * 4 * sizeof(float), nullptr,
                               GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    // Optional-mode targets, allocated with the rest (small next to the mip chains). The half-
    // resolution chain needs a level 1, so it exists only with levels >= 2 (padded sizes even).
    mAccum = gl::Texture::create2D(GL_RGBA32F, width, height, 1);
    mBlurTmp = gl::Texture::create2D(GL_RGBA32F, width, height, 1);
    if (levels >= 2) {
        mHalf = gl::Texture::create2D(GL_RGBA32F, mPadW / 2, mPadH / 2, 1);
        mHalfSums =
            gl::Buffer::create(slots * groupsFor(mPadW / 2) * groupsFor(mPadH / 2) * 4 * sizeof(float),
                               nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    } else {
        mHalf = gl::Texture();
        mHalfSums = gl::Buffer();
    }
    mWidth = width;
    mHeight = height;
    mLevels = levels;
}

// mode 0: geometry and illumination mips of mIllum[illumIndex]; 1: illumination only.
void BiasCompensation::reduce(gl::Pass& pass, int mode, int illumIndex) {
    const ReduceProgram& r = mReduce;
    pass.use(r.program).set(r.mode, mode);
    for (int l = 1; l < mLevels; ++l) {
        const int w = mPadW >> l, h = mPadH >> l;
        const int child = l - 1;
        const int realW = (mWidth + (1 << child) - 1) >> child, realH = (mHeight + (1 << child) - 1) >> child;
        pass.set(r.level, l).set(r.outSize, glm::ivec2(w, h)).set(r.childReal, glm::ivec2(realW, realH));
        pass.image(r.geoIn, mGeo, GL_READ_ONLY, GL_RGBA32F, child)
            .image(r.geoOut, mGeo, GL_WRITE_ONLY, GL_RGBA32F, l)
            .image(r.normalIn, mNormal, GL_READ_ONLY, GL_RGBA32F, child)
            .image(r.normalOut, mNormal, GL_WRITE_ONLY, GL_RGBA32F, l)
            .image(r.illumIn, mIllum[illumIndex], GL_READ_ONLY, GL_RGBA32F, child)
            .image(r.illumOut, mIllum[illumIndex], GL_WRITE_ONLY, GL_RGBA32F, l);
        pass.dispatch(groupsFor(w), groupsFor(h)).barrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    }
    pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT);
}

void BiasCompensation::apply(const FrameInputs& in, const ParamSet& params, const gl::Texture& indirect,
                             gl::PassTimer& timer, Counters& counters) {
    if (!params.has("ssbc_iterations")) return;
    const int iterations = std::clamp(params.getInt("ssbc_iterations"), 0, kMaxIterations);
    const double b = vplClampB(params, in.sceneSize); // 1/m^2
    counters["ssbc_energy_added"] = 0;
    if (iterations == 0 || !(b > 0.0) || !std::isfinite(b) || !in.frame || !in.find("direct") ||
        !in.find("gbuffer.position") || !in.find("gbuffer.normal") || !in.find("gbuffer.albedo") ||
        in.width <= 0 || in.height <= 0 || indirect.width() != in.width || indirect.height() != in.height)
        return;

    // Camera intrinsics from the view-projection: for a perspective projection P and a rigid view V,
    // row 1 of P V is (1 / tan(fov/2)) times V's up row, and row 3 is minus V's z row (the forward axis).
    const glm::mat4& vp = in.frame->viewProj;
    const glm::vec3 row1(vp[0][1], vp[1][1], vp[2][1]);
    const glm::vec3 row3(vp[0][3], vp[1][3], vp[2][3]);
    const float f = glm::length(row1);
    const float tanHalfFov = f > 1e-12f && std::isfinite(f) ? 1.0f / f : 1.0f;
    const float fl = glm::length(row3);
    const glm::vec3 forward = fl > 1e-12f && std::isfinite(fl) ? row3 / fl : glm::vec3(0, 0, -1);

    int maxLevels = 1;
    while ((std::max(in.width, in.height) >> maxLevels) > 0 && maxLevels < 12) ++maxLevels;
    const int levels = std::clamp(params.getInt("ssbc_levels"), 1, maxLevels);
    ensure(in.width, in.height, levels);
    const int groupsX = groupsFor(mPadW), groupsY = groupsFor(mPadH);
    const double grazing = std::clamp(params.getFloat("ssbc_grazing_angle"), 1.0, 90.0);
    const float cosGrazing = grazing >= 90.0 ? 0.0f : static_cast<float>(std::cos(grazing * kDegToRad));

    const gl::Texture& position = in.get("gbuffer.position");
    const gl::Texture& normal = in.get("gbuffer.normal");
    const gl::Texture& albedo = in.get("gbuffer.albedo");
    {
        gl::Pass pass(timer, "ssbc_mips");
        const BaseProgram& p = mBase;
        pass.use(p.program)
            .set(p.tanHalfFov, tanHalfFov)
            .set(p.forward, forward)
            .set(p.cosGrazing, cosGrazing)
            .set(p.withIndirect, params.getEnum("ssbc_input") == "direct" ? 0 : 1);
        pass.texture(p.position, position)
            .texture(p.normal, normal)
            .texture(p.direct, in.get("direct"))
            .texture(p.indirect, indirect)
            .buffer(p.sums, mSums);
        pass.image(p.geoOut, mGeo, GL_WRITE_ONLY)
            .image(p.normalOut, mNormal, GL_WRITE_ONLY)
            .image(p.illumOut, mIllum[0], GL_WRITE_ONLY);
        pass.dispatch(groupsX, groupsY).barrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        reduce(pass, 0, 0);
    }

    // Optional modes: the blur needs the steps' sum on its own (it must not blur the technique's
    // indirect light), so the steps then add into mAccum; half resolution needs a level 1.
    const bool blur = params.has("ssbc_blur") && params.getBool("ssbc_blur");
    const bool half =
        params.has("ssbc_half_resolution") && params.getBool("ssbc_half_resolution") && levels >= 2;
    const gl::Texture& target = blur ? mAccum : indirect;
    if (blur) {
        const float zero[4] = {0, 0, 0, 0};
        glClearTexImage(mAccum.id(), 0, GL_RGBA, GL_FLOAT, zero);
    }
    const int halfGroupsX = half ? groupsFor(mPadW / 2) : 0, halfGroupsY = half ? groupsFor(mPadH / 2) : 0;
    const GLbitfield stepBarrier =
        GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT;

    const float r = static_cast<float>(1.0 / std::sqrt(b));
    for (int k = 1; k <= iterations; ++k) {
        const int src = (k - 1) & 1, dst = k & 1;
        if (k > 1) {
            gl::Pass pass(timer, "ssbc_mips_" + std::to_string(k));
            reduce(pass, 1, src);
        }
        {
            gl::Pass pass(timer, "ssbc_integrate_" + std::to_string(k));
            const IntegrateProgram& p = mIntegrate;
            pass.use(p.program)
                .set(p.b, static_cast<float>(b))
                .set(p.r, r)
                .set(p.tanHalfFov, tanHalfFov)
                .set(p.levels, levels)
                .set(p.solidAngle, static_cast<float>(params.getFloat("ssbc_solid_angle")))
                .set(p.discAngle, static_cast<float>(params.getFloat("ssbc_discontinuity_angle")))
                .set(p.maxVisited, kMaxVisited)
                .set(p.slot, k)
                .set(p.receiverLevel, half ? 1 : 0);
            pass.texture(p.geo, mGeo)
                .texture(p.normal, mNormal)
                .texture(p.illum, mIllum[src])
                .texture(p.albedo, albedo);
            pass.image(p.indirect, target, GL_READ_WRITE).image(p.nextIllum, mIllum[dst], GL_WRITE_ONLY);
            if (half) {
                // Half resolution: the integrate writes only mHalf, its counters go to mHalfSums.
                pass.image(p.halfOut, mHalf, GL_WRITE_ONLY).buffer(p.sums, mHalfSums);
                pass.dispatch(halfGroupsX, halfGroupsY);
            } else {
                pass.buffer(p.sums, mSums).dispatch(groupsX, groupsY);
            }
            pass.barrier(stepBarrier);
        }
        if (half) {
            gl::Pass pass(timer, "ssbc_upsample_" + std::to_string(k));
            const UpsampleProgram& p = mUpsample;
            pass.use(p.program).set(p.slot, k).buffer(p.sums, mSums);
            pass.texture(p.geo, mGeo)
                .texture(p.normal, mNormal)
                .texture(p.half, mHalf)
                .texture(p.albedo, albedo);
            pass.image(p.target, target, GL_READ_WRITE).image(p.nextIllum, mIllum[dst], GL_WRITE_ONLY);
            pass.dispatch(groupsX, groupsY).barrier(stepBarrier);
        }
    }

    if (blur) {
        gl::Pass pass(timer, "ssbc_blur");
        const BlurProgram& p = mBlur;
        const GLbitfield blurBarrier = GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT;
        pass.use(p.program).texture(p.geo, mGeo).texture(p.normal, mNormal).buffer(p.sums, mSums);
        // Pass 0: mAccum / W -> mBlurTmp; pass 1: gather into the indirect radiance.
        pass.set(p.pass, 0).texture(p.source, mAccum).image(p.out, mBlurTmp, GL_WRITE_ONLY);
        pass.dispatch(groupsFor(in.width), groupsFor(in.height)).barrier(blurBarrier);
        pass.set(p.pass, 1).texture(p.source, mBlurTmp).image(p.out, indirect, GL_READ_WRITE);
        pass.dispatch(groupsFor(in.width), groupsFor(in.height)).barrier(blurBarrier);
    }

    // Counters: one read-back of the per-group sums (synchronises with the last step).
    const size_t groups = static_cast<size_t>(groupsX) * static_cast<size_t>(groupsY);
    std::vector<float> sums(groups * 4 * static_cast<size_t>(iterations + 1));
    glGetNamedBufferSubData(mSums.id(), 0, static_cast<GLsizeiptr>(sums.size() * sizeof(float)), sums.data());
    double clamped = 0, added = 0, visited = 0, covered = 0, maxVisited = 0, fallback = 0;
    for (size_t g = 0; g < groups; ++g) clamped += sums[g * 4];
    for (int k = 1; k <= iterations; ++k) {
        double step = 0;
        for (size_t g = 0; g < groups; ++g) {
            const float* s = &sums[(static_cast<size_t>(k) * groups + g) * 4];
            step += s[0];
            if (half) {
                fallback += s[3]; // the upsampling's w: pixels that took the nearest block
            } else {
                visited += s[1];
                maxVisited = std::max(maxVisited, static_cast<double>(s[2]));
                covered += s[3];
            }
        }
        counters["ssbc_energy_step" + std::to_string(k)] = step;
        added += step;
    }
    if (half) {
        // Sample counts per half-resolution receiver, from the integrate's own sums.
        const size_t halfGroups = static_cast<size_t>(halfGroupsX) * static_cast<size_t>(halfGroupsY);
        std::vector<float> hs(halfGroups * 4 * static_cast<size_t>(iterations + 1));
        glGetNamedBufferSubData(mHalfSums.id(), 0, static_cast<GLsizeiptr>(hs.size() * sizeof(float)),
                                hs.data());
        for (int k = 1; k <= iterations; ++k)
            for (size_t g = 0; g < halfGroups; ++g) {
                const float* s = &hs[(static_cast<size_t>(k) * halfGroups + g) * 4];
                visited += s[1];
                maxVisited = std::max(maxVisited, static_cast<double>(s[2]));
                covered += s[3];
            }
        counters["ssbc_half_resolution"] = 1;
        counters["ssbc_upsample_fallback"] = fallback;
    }
    counters["ssbc_clamped_energy"] = clamped;
    counters["ssbc_energy_added"] = added;
    counters["ssbc_energy_ratio"] = clamped > 0 ? added / clamped : 0.0;
    counters["ssbc_samples_mean"] = covered > 0 ? visited / covered : 0.0;
    counters["ssbc_samples_max"] = maxVisited;
    counters["ssbc_levels"] = levels;
}

} // namespace gis

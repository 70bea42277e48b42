#include "gi/common/BiasCompensation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/glm.hpp>

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

float vplInverseClampB(const ParamSet& params) {
    if (!params.has("clamp_b")) return 0.0f;
    const double b = params.getFloat("clamp_b");
    return b > 0.0 && std::isfinite(b) ? static_cast<float>(1.0 / b) : 0.0f;
}

void setVplClamp(const gl::Program& program, const ParamSet& params) {
    const GLint loc = program.uniform("uVplInvClampB");
    if (loc >= 0) glProgramUniform1f(program.id(), loc, vplInverseClampB(params));
}

BiasCompensation::BiasCompensation() {
    mBase = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_base.comp"}});
    mReduce = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_reduce.comp"}});
    mIntegrate = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_integrate.comp"}});
    mUpsample = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_upsample.comp"}});
    mBlur = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/ssbc_blur.comp"}});
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
void BiasCompensation::reduce(int mode, int illumIndex) {
    glUseProgram(mReduce.id());
    glUniform1i(mReduce.uniform("uMode"), mode);
    for (int l = 1; l < mLevels; ++l) {
        const int w = mPadW >> l, h = mPadH >> l;
        const int child = l - 1;
        const int realW = (mWidth + (1 << child) - 1) >> child, realH = (mHeight + (1 << child) - 1) >> child;
        glUniform1i(mReduce.uniform("uLevel"), l);
        glUniform2i(mReduce.uniform("uOutSize"), w, h);
        glUniform2i(mReduce.uniform("uChildReal"), realW, realH);
        glBindImageTexture(0, mGeo.id(), child, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(1, mGeo.id(), l, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glBindImageTexture(2, mNormal.id(), child, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(3, mNormal.id(), l, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glBindImageTexture(4, mIllum[illumIndex].id(), child, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(5, mIllum[illumIndex].id(), l, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(static_cast<GLuint>(groupsFor(w)), static_cast<GLuint>(groupsFor(h)), 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
}

void BiasCompensation::apply(const FrameInputs& in, const ParamSet& params, const gl::Texture& indirect,
                             gl::PassTimer& timer, Counters& counters) {
    if (!params.has("ssbc_iterations")) return;
    const int iterations = std::clamp(params.getInt("ssbc_iterations"), 0, kMaxIterations);
    const double b = params.getFloat("clamp_b");
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

    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mSums.id());
    timer.begin("ssbc_mips");
    glUseProgram(mBase.id());
    glUniform1f(mBase.uniform("uTanHalfFov"), tanHalfFov);
    glUniform3f(mBase.uniform("uForward"), forward.x, forward.y, forward.z);
    glUniform1f(mBase.uniform("uCosGrazing"), cosGrazing);
    glUniform1i(mBase.uniform("uWithIndirect"), params.getEnum("ssbc_input") == "direct" ? 0 : 1);
    glBindTextureUnit(0, in.find("gbuffer.position")->id());
    glBindTextureUnit(1, in.find("gbuffer.normal")->id());
    glBindTextureUnit(2, in.find("direct")->id());
    glBindTextureUnit(3, indirect.id());
    glBindImageTexture(0, mGeo.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindImageTexture(1, mNormal.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindImageTexture(2, mIllum[0].id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(static_cast<GLuint>(groupsX), static_cast<GLuint>(groupsY), 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    reduce(0, 0);
    timer.end();

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

    const float r = static_cast<float>(1.0 / std::sqrt(b));
    for (int k = 1; k <= iterations; ++k) {
        const int src = (k - 1) & 1, dst = k & 1;
        if (k > 1) {
            timer.begin("ssbc_mips_" + std::to_string(k));
            reduce(1, src);
            timer.end();
        }
        timer.begin("ssbc_integrate_" + std::to_string(k));
        glUseProgram(mIntegrate.id());
        glUniform1f(mIntegrate.uniform("uB"), static_cast<float>(b));
        glUniform1f(mIntegrate.uniform("uR"), r);
        glUniform1f(mIntegrate.uniform("uTanHalfFov"), tanHalfFov);
        glUniform1i(mIntegrate.uniform("uLevels"), levels);
        glUniform1f(mIntegrate.uniform("uSolidAngle"),
                    static_cast<float>(params.getFloat("ssbc_solid_angle")));
        glUniform1f(mIntegrate.uniform("uDiscAngle"),
                    static_cast<float>(params.getFloat("ssbc_discontinuity_angle")));
        glUniform1i(mIntegrate.uniform("uMaxVisited"), kMaxVisited);
        glUniform1i(mIntegrate.uniform("uSlot"), k);
        glUniform1i(mIntegrate.uniform("uReceiverLevel"), half ? 1 : 0);
        glBindTextureUnit(0, mGeo.id());
        glBindTextureUnit(1, mNormal.id());
        glBindTextureUnit(2, mIllum[src].id());
        glBindTextureUnit(3, in.find("gbuffer.albedo")->id());
        glBindImageTexture(0, target.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(1, mIllum[dst].id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        if (half) {
            // Half resolution: the integrate writes only mHalf, its counters go to mHalfSums.
            glBindImageTexture(2, mHalf.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mHalfSums.id());
            glDispatchCompute(static_cast<GLuint>(halfGroupsX), static_cast<GLuint>(halfGroupsY), 1);
        } else {
            glDispatchCompute(static_cast<GLuint>(groupsX), static_cast<GLuint>(groupsY), 1);
        }
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                        GL_BUFFER_UPDATE_BARRIER_BIT);
        timer.end();
        if (half) {
            timer.begin("ssbc_upsample_" + std::to_string(k));
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mSums.id());
            glUseProgram(mUpsample.id());
            glUniform1i(mUpsample.uniform("uSlot"), k);
            glBindTextureUnit(0, mGeo.id());
            glBindTextureUnit(1, mNormal.id());
            glBindTextureUnit(2, mHalf.id());
            glBindTextureUnit(3, in.find("gbuffer.albedo")->id());
            glBindImageTexture(0, target.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
            glBindImageTexture(1, mIllum[dst].id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
            glDispatchCompute(static_cast<GLuint>(groupsX), static_cast<GLuint>(groupsY), 1);
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                            GL_BUFFER_UPDATE_BARRIER_BIT);
            timer.end();
        }
    }

    if (blur) {
        timer.begin("ssbc_blur");
        glUseProgram(mBlur.id());
        glBindTextureUnit(0, mGeo.id());
        glBindTextureUnit(1, mNormal.id());
        // Pass 0: mAccum / W -> mBlurTmp; pass 1: gather into the indirect radiance.
        glUniform1i(mBlur.uniform("uPass"), 0);
        glBindTextureUnit(2, mAccum.id());
        glBindImageTexture(0, mBlurTmp.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(static_cast<GLuint>(groupsFor(in.width)), static_cast<GLuint>(groupsFor(in.height)),
                          1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        glUniform1i(mBlur.uniform("uPass"), 1);
        glBindTextureUnit(2, mBlurTmp.id());
        glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glDispatchCompute(static_cast<GLuint>(groupsFor(in.width)), static_cast<GLuint>(groupsFor(in.height)),
                          1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        timer.end();
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
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
}

} // namespace gis

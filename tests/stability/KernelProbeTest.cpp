// The VPL transport kernels (shaders/gi/common/vpl_transport.glsl, digest S.3 K1-K3) evaluated on
// the GPU for hand-placed receiver/VPL pairs: S.4 cases 1 (coincident and 1e-7 pairs), 2 (grazing
// and back-facing) and 8 (on-axis disk, K2 exactness). Every VPL technique uses these functions,
// so the results fill the "kernels" column of docs/stability.md. A compute probe that includes the
// real shader file is built from a temporary GI_SHADER_DIR (includes fall back to the embedded
// copies), so the probe always tests the shipped kernels.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <glm/gtc/constants.hpp>
#include <unistd.h>

#include "../common/ShaderProbe.h"
#include "StabilityLab.h"
#include "gl/Shader.h"

using namespace gis;
using namespace gis::stability;

namespace {

struct Pair {
    glm::vec4 receiverPos, receiverNormal, vplPos, vplNormal; // vplNormal.w: disk area A
    glm::vec4 flux;                                           // rgb flux; w: min_distance (K1)
};
struct Result {
    glm::vec4 k; // x: K1 (point + distance clamp, or K3 when b is set), y: K2 (disk, or K3),
                 // z: K4 (second_order's back-side kernel, gi/second_order/k4.glsl)
};

const char* kProbe = R"(#version 450 core
#include "common.glsl"
#include "gi/common/vpl_transport.glsl"
#include "gi/second_order/k4.glsl"
layout(local_size_x = 1) in;
struct Pair { vec4 receiverPos, receiverNormal, vplPos, vplNormal, flux; };
layout(std430, binding = 0) readonly buffer Pairs { Pair gPairs[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 gResults[]; };
void main() {
    Pair p = gPairs[gl_WorkGroupID.x];
    vec3 k1 = vplIrradiance(p.receiverPos.xyz, p.receiverNormal.xyz, p.vplPos.xyz, p.vplNormal.xyz, p.flux.rgb, p.flux.w);
    vec3 k2 = vplIrradianceDisk(p.receiverPos.xyz, p.receiverNormal.xyz, p.vplPos.xyz, p.vplNormal.xyz, p.flux.rgb, p.vplNormal.w);
    Vpl v;
    v.position = vec4(p.vplPos.xyz, 1.0);
    v.normal = p.vplNormal;
    v.flux = vec4(p.flux.rgb, 1.0);
    vec3 toLight;
    vec3 k4 = backIrradiance(p.receiverPos.xyz, p.receiverNormal.xyz, v, p.flux.w, toLight);
    gResults[gl_WorkGroupID.x] = vec4(k1.r, k2.r, k4.r, 0.0);
}
)";

/// Evaluates the kernels for `pairs` with K3's bound b (0: K1/K2 as configured).
std::vector<Result> evaluate(const std::vector<Pair>& pairs, float clampB) {
    rendererFor("rsm_gather"); // a current context
    static gl::Program program;
    if (!program) program = test::buildComputeProbe("kernel_probe", kProbe);
    gl::Buffer in = gl::Buffer::create(static_cast<GLsizeiptr>(pairs.size() * sizeof(Pair)), pairs.data());
    gl::Buffer out = gl::Buffer::create(static_cast<GLsizeiptr>(pairs.size() * sizeof(Result)));
    glUseProgram(program.id());
    glUniform1f(program.location("uVplInvClampB").location, clampB > 0 ? 1.0f / clampB : 0.0f);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
    glDispatchCompute(static_cast<GLuint>(pairs.size()), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<Result> r(pairs.size());
    glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(r.size() * sizeof(Result)), r.data());
    return r;
}

Pair pair(glm::vec3 rp, glm::vec3 rn, glm::vec3 vp, glm::vec3 vn, float area, float flux, float minDistance) {
    return Pair{glm::vec4(rp, 1), glm::vec4(rn, 0), glm::vec4(vp, 1), glm::vec4(vn, area),
                glm::vec4(flux, flux, flux, minDistance)};
}

class KernelCell : public ::testing::Test {
protected:
    void open(const std::string& caseId) { beginCell(caseId, "kernels"); }
    void TearDown() override { endCell(HasFailure(), IsSkipped()); }
};

} // namespace

// Case 1: a VPL at the shading point and a VPL on the adjacent perpendicular wall at 1e-7 m.
TEST_F(KernelCell, C01_CoincidentVpl) {
    open("C01_CoincidentVpl");
    const float phi = 2.0f, area = 1e-3f, b = 10.0f, dmin = 0.1f;
    std::vector<Pair> pairs;
    // Coincident, the receiver on the VPL disk's own side (equal normals): 0 for every kernel (K2's
    // limit Phi/A <n_r, -n_l>+ is 0 here; a facing coincident pair gives Phi/A, case 8).
    pairs.push_back(pair({0, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, area, phi, dmin));
    // Perpendicular walls meeting at the origin, VPL on the floor (normal +y), receiver on the wall
    // (normal +x), both 1e-7 / sqrt(2) from the edge, and a sweep of distances down to 1e-30 m.
    for (float d : {1e-30f, 1e-20f, 1e-12f, 1e-9f, 1e-7f, 1e-5f, 1e-3f, 1e-1f, 1.0f}) {
        const float a = d / std::sqrt(2.0f);
        pairs.push_back(pair({0, a, 0}, {1, 0, 0}, {a, 0, 0}, {0, 1, 0}, area, phi, dmin));
        pairs.push_back(pair({0, a, 0}, {1, 0, 0}, {a, 0, 0}, {0, 1, 0}, area, phi, 0.0f));  // no clamp
        pairs.push_back(pair({0, 0, 0}, {0, 1, 0}, {0, d, 0}, {0, -1, 0}, area, phi, dmin)); // facing pair
    }
    const std::vector<Result> plain = evaluate(pairs, 0.0f), k3 = evaluate(pairs, b);
    const double pi = glm::pi<double>();
    for (size_t i = 0; i < pairs.size(); ++i) {
        SCOPED_TRACE("pair " + std::to_string(i));
        const float dminI = pairs[i].flux.w;
        for (float v : {plain[i].k.x, plain[i].k.y, k3[i].k.x, k3[i].k.y}) {
            EXPECT_TRUE(std::isfinite(v));
            EXPECT_GE(v, 0.0f);
        }
        if (dminI > 0) {
            EXPECT_LE(plain[i].k.x, phi / (pi * dminI * dminI) * (1 + 1e-5)) << "K1 above Phi/(pi dmin^2)";
        }
        EXPECT_LE(plain[i].k.y, phi / area * (1 + 1e-5)) << "K2 above Phi/A";
        EXPECT_TRUE(std::isfinite(plain[i].k.z));
        EXPECT_GE(plain[i].k.z, 0.0f);
        if (dminI > 0) {
            EXPECT_LE(plain[i].k.z, phi / (pi * dminI * dminI) * (1 + 1e-5)) << "K4 above Phi/(pi dmin^2)";
        }
        EXPECT_LE(k3[i].k.x, phi * b / pi * (1 + 1e-5)) << "K3 (point form) above Phi b/pi";
        EXPECT_LE(k3[i].k.y, phi * b / pi * (1 + 1e-5)) << "K3 (disk form) above Phi b/pi";
    }
    EXPECT_EQ(plain[0].k.x, 0.0f);
    EXPECT_EQ(plain[0].k.y, 0.0f);
    EXPECT_EQ(k3[0].k.x, 0.0f);
    EXPECT_EQ(plain[0].k.z, 0.0f);
    note("coincident pair", "0 for K1, K2, K3, K4");
    note("max K2*A/Phi", [&] {
        double m = 0;
        for (const Result& r : plain) m = std::max(m, double(r.k.y) * area / phi);
        return m;
    }());
}

// Case 2: cos = 0 exactly, cos slightly below 0, and a VPL facing away contribute exactly 0.
TEST_F(KernelCell, C02_GrazingBackFacing) {
    open("C02_GrazingBackFacing");
    std::vector<Pair> pairs;
    const float eps = 1e-6f;
    // Receiver normal at exactly 90 degrees to w (VPL in the receiver's tangent plane).
    pairs.push_back(pair({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {-1, 0, 0}, 1e-3f, 1.0f, 0.1f));
    // 90 + 1e-6 degrees: the VPL slightly below the tangent plane.
    const float t = std::tan(glm::radians(eps));
    pairs.push_back(pair({0, 0, 0}, {0, 1, 0}, {1, -t, 0}, {-1, 0, 0}, 1e-3f, 1.0f, 0.1f));
    // VPL normal facing away from the receiver.
    pairs.push_back(pair({0, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}, 1e-3f, 1.0f, 0.1f));
    // Both back-facing.
    pairs.push_back(pair({0, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 1, 0}, 1e-3f, 1.0f, 0.1f));
    for (float b : {0.0f, 10.0f}) {
        const std::vector<Result> r = evaluate(pairs, b);
        for (size_t i = 0; i < r.size(); ++i) {
            EXPECT_EQ(r[i].k.x, 0.0f) << "pair " << i << " b " << b;
            EXPECT_EQ(r[i].k.y, 0.0f) << "pair " << i << " b " << b;
            // K4 reads the back side: 0 here too (front, tangent plane, or a light facing away).
            EXPECT_EQ(r[i].k.z, 0.0f) << "K4, pair " << i;
        }
    }
    // K4 is non-zero only on the back side (S.4 case 2): a light 1 m behind the receiver, facing it.
    const std::vector<Pair> back = {pair({0, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, -1, 0}, 1e-3f, 1.0f, 0.1f),
                                    pair({0, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0, -1, 0}, 1e-3f, 1.0f, 0.1f)};
    const std::vector<Result> rb = evaluate(back, 0.0f);
    EXPECT_EQ(rb[0].k.x, 0.0f) << "K1 on the back side";
    EXPECT_EQ(rb[0].k.y, 0.0f) << "K2 on the back side";
    EXPECT_NEAR(rb[0].k.z, 1.0 / glm::pi<double>(), 1e-6) << "K4 = Phi/pi cos cos / d^2 on the back side";
    EXPECT_EQ(rb[1].k.z, 0.0f) << "K4 on the front side";
    EXPECT_GT(rb[1].k.x, 0.0f) << "K1 on the front side";
    note("grazing / back-facing contributions",
         "exactly 0 (K1, K2, K3); K4 only on the back side (Phi/pi at 1 m)");
}

// Case 14 (linearity): splitting every VPL into two at the same position with half the flux leaves
// the result unchanged, for every kernel (halving is exact in floating point, so 2 K(Phi/2) must equal
// K(Phi) bit for bit).
TEST_F(KernelCell, C14_ScaleAndLinearity) {
    open("C14_ScaleAndLinearity");
    std::vector<Pair> whole, half;
    const float phi = 3.0f;
    for (float d : {1e-4f, 0.05f, 0.3f, 2.0f, 40.0f})
        for (const glm::vec3& dir :
             {glm::vec3(0, 1, 0), glm::normalize(glm::vec3(1, 1, 0.5f)), glm::vec3(0, -1, 0)}) {
            whole.push_back(pair({0, 0, 0}, {0, 1, 0}, d * dir, -dir, 1e-2f, phi, 0.1f));
            half.push_back(pair({0, 0, 0}, {0, 1, 0}, d * dir, -dir, 1e-2f, 0.5f * phi, 0.1f));
        }
    int compared = 0;
    for (float b : {0.0f, 10.0f}) {
        const std::vector<Result> a = evaluate(whole, b), h = evaluate(half, b);
        for (size_t i = 0; i < a.size(); ++i)
            for (int k = 0; k < 3; ++k) {
                EXPECT_EQ(a[i].k[k], 2.0f * h[i].k[k]) << "pair " << i << " kernel " << k << " b " << b;
                ++compared;
            }
    }
    note("split VPL: 2 K(Phi/2) == K(Phi)", std::to_string(compared) + " kernel values, bit for bit (K1-K4)");
}

// Case 8: K2 with A = pi R^2, both cosines 1, gives E = B R^2 / (h^2 + R^2) exactly.
TEST_F(KernelCell, C08_OnAxisDisk) {
    open("C08_OnAxisDisk");
    const float radius = 0.5f, exitance = 3.0f;
    const float area = glm::pi<float>() * radius * radius;
    std::vector<float> heights = {0.0f, 1e-6f, radius, 100.0f * radius};
    std::vector<Pair> pairs;
    for (float h : heights)
        pairs.push_back(pair({0, h, 0}, {0, -1, 0}, {0, 0, 0}, {0, 1, 0}, area, exitance * area, 0));
    const std::vector<Result> r = evaluate(pairs, 0.0f);
    double worst = 0;
    for (size_t i = 1; i < heights.size(); ++i) {
        const double h = heights[i];
        const double expected = exitance * radius * radius / (h * h + radius * radius);
        const double rel = std::abs(r[i].k.y - expected) / expected;
        worst = std::max(worst, rel);
        EXPECT_LT(rel, 1e-5) << "h = " << h;
    }
    note("max rel. error h in {1e-6, R, 100R}", worst);
    // h = 0: the receiver coincides with the VPL's point; K2 returns its bounded limit B there (the
    // point kernel keeps case 1's fallback 0).
    note("E(h=0)/B", r[0].k.y / exitance);
    EXPECT_NEAR(r[0].k.y, exitance, 1e-5f * exitance) << "K2 at h = 0";
    EXPECT_EQ(r[0].k.x, 0.0f) << "K1 at h = 0: coincident fallback";
}

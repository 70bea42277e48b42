// Glossy VPL transport (issue #11; 000 §3.4 supports arbitrary BRDFs with per-VPL evaluation): on top
// of the diffuse bounce every VPL technique computes, a VPL on a specular surface also sends light
// through its own specular lobe (light from the spot, mirrored towards the receiver), and a specular
// receiver reflects each VPL's light through its lobe towards the eye. Both use the reflection model
// of render/brdf.glsl and only surfaces at least uGlossyMinRoughness rough: smoother ones get their
// specular light from the reflection passes (environment probe, planar mirrors), and VPL point
// samples would miss their sharp lobes (000 §3.4).
//
// A VPL of incident flux Phi_in reflects intensity f(l, w) Phi_in cos(theta_w) towards w, so with the
// kernel K = cos_l cos_r / (pi d^2) (or its disk / clamped form) its specular lobe gives the receiver
// E_s = pi f_s(l, w) Phi_in K: the same kernel evaluated with Phi_in, times pi f_s.
// Needs vpl_transport.glsl and render/brdf.glsl included before it.
#ifndef GIS_VPL_GLOSSY_GLSL
#define GIS_VPL_GLOSSY_GLSL

layout(std430, binding = 1) readonly buffer VplGlossyBuffer {
    VplGlossy gVplGlossy[];
};

uniform int uGlossy;               // 1: glossy VPL transport on (FrameInputs::glossy)
uniform float uGlossyMinRoughness; // glossy_split: lobes at least this rough

bool glossyLobe(vec4 spec) { return brdfHasSpecular(spec.rgb) && spec.a >= uGlossyMinRoughness; }

// VPL `v` (glossy data `g`) seen from receiver p (normal n, unit direction to the eye wo, specular
// `spec`): e is the VPL's diffuse irradiance already times `visibility`. Adds the irradiance of the
// VPL's specular lobe to eExtra (for the receiver's diffuse lobe) and the radiance through the
// receiver's specular lobe to lGlossy.
void vplGlossyAccumulate(Vpl v, VplGlossy g, vec3 e, float visibility, float minDistance, vec3 p, vec3 n,
                         vec3 wo, vec4 spec, bool glossyReceiver, inout vec3 eExtra, inout vec3 lGlossy) {
    vec3 toVpl = v.position.xyz - p;
    float d2 = dot(toVpl, toVpl);
    if (!(d2 > 1e-20) || !(v.position.w > 0.5)) return;
    vec3 wi = toVpl * inversesqrt(d2);
    vec3 total = e;
    if (g.incident.a > 0.5 && glossyLobe(g.specular)) {
        int light = int(g.incident.a - 0.5); // incident.a is 1 + the light's index
        vec3 l, irradiance;
        float dist;
        if (lightIncidence(light, v.position.xyz, l, dist, irradiance)) {
            Vpl incoming = v;
            incoming.flux.rgb = g.incident.rgb;
            vec3 eIn = vplIrradianceSelected(p, n, incoming, minDistance) * visibility;
            vec3 fs = brdfSpecular(g.specular.rgb, g.specular.a, int(gFrame.shadingInfo.x), v.normal.xyz,
                                   l, -wi);
            vec3 es = max(sanitize(kPi * fs * eIn), vec3(0.0));
            eExtra += es;
            total += es;
        }
    }
    if (glossyReceiver) lGlossy += brdfSpecular(spec.rgb, spec.a, int(gFrame.shadingInfo.x), n, wi, wo) * total;
}

#endif

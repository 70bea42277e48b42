// Receiver geometry of a patch of any level: level 0 reads the G-buffer (eye_pixel.glsl), coarser
// levels the atlas means. Bindings 11-13 hold the atlas geometry textures.
layout(binding = 11) uniform sampler2D uAtlasPosition; // xyz mean position (m); w covered pixels
layout(binding = 12) uniform sampler2D uAtlasNormal;   // xyz mean unit normal
layout(binding = 13) uniform sampler2D uAtlasAlbedo;   // rgb mean albedo

struct EyePatch {
    vec3 position, normal, albedo;
    float covered; // pixels of the patch that see geometry
    ivec2 pixel;   // the full-resolution pixel at the patch's centre (its material sample)
};

EyePatch eyePatch(int level, ivec2 t) {
    EyePatch p;
    if (level == 0) {
        vec4 pos = texelFetch(gPosition, t, 0);
        p.position = pos.xyz;
        p.normal = texelFetch(gNormal, t, 0).xyz;
        p.albedo = texelFetch(gAlbedo, t, 0).rgb;
        p.covered = pos.w > 0.5 ? 1.0 : 0.0;
        p.pixel = t;
    } else {
        ivec2 a = eyeAtlas(level, t);
        vec4 pos = texelFetch(uAtlasPosition, a, 0);
        p.position = pos.xyz;
        p.normal = texelFetch(uAtlasNormal, a, 0).xyz;
        p.albedo = texelFetch(uAtlasAlbedo, a, 0).rgb;
        p.covered = pos.w;
        p.pixel = min((t << level) + ivec2((1 << level) / 2), ivec2(gFrame.viewport.xy) - 1);
    }
    return p;
}

uint packPatch(int level, ivec2 t) { return (uint(level) << 28) | (uint(t.y) << 14) | uint(t.x); }
int patchLevel(uint item) { return int(item >> 28); }
ivec2 patchTexel(uint item) { return ivec2(int(item & 0x3FFFu), int((item >> 14) & 0x3FFFu)); }

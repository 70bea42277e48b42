// Reference cache: content-hash keys and EXR files carrying the render's metadata (OpenImageIO).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <system_error>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include "core/Error.h"
#include "core/Log.h"
#include "frame/LightModel.h"
#include "reference/ContentHash.h"
#include "reference/ReferenceRenderer.h"

namespace gis {
namespace reference {

// Bump when the renderer's output for the same request changes (estimators, epsilon, sampling), so old
// cache files stop matching.
// 2: non-diffuse materials (scene/Brdf.h: metallic, roughness, specular) and the frame parameters
// specular_lobe and effect_specular.
// 3: every light, range windows.
// 4: the pixel means' variance, the noise target; 5: materials' alpha cutouts, metallic-roughness,
// emissive and normal textures, vertex colours
constexpr const char* kKeyVersion = "gis-reference-5";

std::string sceneDigest(const Scene& scene) {
    Hasher h;
    h.value(scene.meshes.size());
    for (const Mesh& m : scene.meshes) {
        h.value(m.positions.size());
        h.bytes(m.positions.data(), m.positions.size() * sizeof(glm::vec3));
        h.value(m.normals.size());
        h.bytes(m.normals.data(), m.normals.size() * sizeof(glm::vec3));
        h.value(m.texcoords.size());
        h.bytes(m.texcoords.data(), m.texcoords.size() * sizeof(glm::vec2));
        h.value(m.colors.size());
        h.bytes(m.colors.data(), m.colors.size() * sizeof(glm::vec4));
        h.value(m.tangents.size());
        h.bytes(m.tangents.data(), m.tangents.size() * sizeof(glm::vec4));
        h.value(m.indices.size());
        h.bytes(m.indices.data(), m.indices.size() * sizeof(std::uint32_t));
        h.value(m.material);
        // Only instanced meshes add to the digest, so the cache keys of flattened scenes hold.
        if (m.instanced()) {
            h.value(m.instances.size());
            h.bytes(m.instances.data(), m.instances.size() * sizeof(glm::mat4));
        }
    }
    h.value(scene.materials.size());
    for (const Material& m : scene.materials) {
        h.value(m.baseColor);
        h.value(m.baseColorTexture);
        h.value(m.metallic);
        h.value(m.roughness);
        h.value(m.specular);
        h.value(m.emissive);
        h.value(static_cast<int>(m.alphaMode));
        h.value(m.alphaCutoff);
        h.value(m.metallicRoughnessTexture);
        h.value(m.emissiveTexture);
        h.value(m.normalTexture);
        h.value(m.normalScale);
    }
    h.value(scene.textures.size());
    for (const TextureImage& t : scene.textures) {
        h.value(t.width);
        h.value(t.height);
        h.value(t.srgb);
        h.value(t.rgba.size());
        h.bytes(t.rgba.data(), t.rgba.size());
    }
    h.value(scene.bounds.min); // the ray epsilon scales with the bounds
    h.value(scene.bounds.max);
    return h.hex();
}

std::string requestKey(const std::string& digest, const FrameState& state, const ReferenceOptions& options) {
    Hasher h;
    h.text(kKeyVersion);
    h.text(digest);
    const Camera& c = state.camera;
    h.value(c.position);
    h.value(c.target);
    h.value(c.up);
    h.value(c.yfovRadians);
    h.value(c.znear);
    h.value(c.zfar);
    h.value(static_cast<int>(state.lights.size()));
    for (const FrameLight& fl : state.lights) {
        const Light& l = fl.light;
        h.value(static_cast<int>(l.type));
        h.value(l.position);
        h.value(l.direction);
        h.value(l.color);
        h.value(l.intensity);
        h.value(l.innerConeAngle);
        h.value(l.outerConeAngle);
        h.value(l.range);
        h.value(fl.enabled);
    }
    // Which of them are rendered.
    h.value(state.frameParams.has("max_lights") ? state.frameParams.getInt("max_lights") : kDefaultMaxLights);
    h.value(state.width);
    h.value(state.height);
    // The frame parameters the reflection model reads (ReferenceRenderer.cpp ShadingModel); a state
    // without the frame table renders with the defaults, hashed as such.
    const ParamSet& fp = state.frameParams;
    h.text(fp.has("specular_lobe") ? fp.getEnum("specular_lobe") : std::string("ggx"));
    // auto and on shade alike (ShadingModel), so only off changes the key.
    h.value(fp.has("effect_specular") && fp.getEnum("effect_specular") == "off");
    h.text(options.mode);
    h.value(options.spp);
    h.value(options.timeBudgetSeconds);
    h.value(options.maxDepth);
    h.value(options.seed);
    h.value(options.jitter);
    h.value(options.causticMinRoughness);
    h.value(options.noiseTarget);
    h.value(options.noiseOfIndirect);
    return h.hex();
}

} // namespace reference

std::string referenceCacheKey(const Scene& scene, const FrameState& state, const ReferenceOptions& options) {
    return reference::requestKey(reference::sceneDigest(scene), state, options);
}

void writeReferenceExr(const std::string& path, const ReferenceImage& image) {
    const size_t expected =
        static_cast<size_t>(std::max(image.width, 0)) * static_cast<size_t>(std::max(image.height, 0)) * 3;
    if (image.width <= 0 || image.height <= 0 || image.rgb.size() != expected)
        throw Error("reference: cannot write '" + path + "': image size and pixel data disagree");
    // A unique temporary name in the same directory, renamed into place: readers never see half a file
    // and concurrent writers of the same key each publish a whole one.
    static std::atomic<unsigned> counter{0};
    const std::string tmp =
        path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++) + ".exr";
    auto out = OIIO::ImageOutput::create(tmp);
    if (!out) throw Error("reference: cannot write '" + path + "': " + OIIO::geterror());
    const bool withVariance = image.variance.size() == expected;
    const int channels = withVariance ? 6 : 3;
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::FLOAT);
    if (withVariance) spec.channelnames = {"R", "G", "B", "variance.R", "variance.G", "variance.B"};
    std::vector<float> pixels;
    if (withVariance) {
        pixels.resize(expected * 2);
        for (size_t i = 0, n = expected / 3; i < n; ++i)
            for (size_t c = 0; c < 3; ++c) {
                pixels[i * 6 + c] = image.rgb[i * 3 + c];
                pixels[i * 6 + 3 + c] = image.variance[i * 3 + c];
            }
    }
    spec.attribute("compression", "zip");
    spec.attribute("gis:mode", image.mode);
    spec.attribute("gis:spp", image.spp);
    spec.attribute("gis:seconds", static_cast<float>(image.seconds));
    spec.attribute("gis:key", image.key);
    const bool ok =
        out->open(tmp, spec) &&
        out->write_image(OIIO::TypeDesc::FLOAT, withVariance ? pixels.data() : image.rgb.data()) &&
        out->close();
    if (!ok) {
        const std::string why = out->geterror();
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw Error("reference: cannot write '" + path + "': " + why);
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw Error("reference: cannot move the EXR into place at '" + path + "'");
    }
}

ReferenceImage readReferenceExr(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "file not found");
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw InputError(path, "cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 3 || spec.depth != 1)
        throw InputError(path, "expected an RGB image, got " + std::to_string(spec.nchannels) + " channels");
    ReferenceImage img;
    img.width = spec.width;
    img.height = spec.height;
    img.mode = spec.get_string_attribute("gis:mode");
    img.spp = spec.get_int_attribute("gis:spp", 0);
    img.seconds = spec.get_float_attribute("gis:seconds", 0.0f);
    img.key = spec.get_string_attribute("gis:key");
    const size_t pixels = static_cast<size_t>(img.width) * static_cast<size_t>(img.height);
    std::vector<float> all(pixels * static_cast<size_t>(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        throw InputError(path, "cannot read pixels: " + in->geterror());
    const auto stride = static_cast<size_t>(spec.nchannels);
    img.rgb.resize(pixels * 3);
    for (size_t i = 0; i < pixels; ++i)
        for (size_t c = 0; c < 3; ++c) {
            const float v = all[i * stride + c];
            img.rgb[i * 3 + c] = std::isfinite(v) && v > 0.0f ? v : 0.0f; // keep the no-NaN/negative promise
        }
    // The pixel means' variance, when the file carries it (writeReferenceExr's channel names).
    int varianceChannel[3] = {-1, -1, -1};
    for (int c = 0; c < spec.nchannels; ++c)
        for (int k = 0; k < 3; ++k)
            if (spec.channel_name(c) == std::string("variance.") + "RGB"[k]) varianceChannel[k] = c;
    if (varianceChannel[0] >= 0 && varianceChannel[1] >= 0 && varianceChannel[2] >= 0) {
        img.variance.resize(pixels * 3);
        for (size_t i = 0; i < pixels; ++i)
            for (size_t k = 0; k < 3; ++k) {
                const float v = all[i * stride + static_cast<size_t>(varianceChannel[k])];
                img.variance[i * 3 + k] = std::isfinite(v) && v > 0.0f ? v : 0.0f;
            }
    }
    return img;
}

ReferenceImage renderReferenceCached(const Scene& scene, const FrameState& state,
                                     const ReferenceOptions& options, const std::string& cacheDir,
                                     bool* cacheHit) {
    validateReferenceOptions(options);
    if (cacheHit) *cacheHit = false;
    const std::string key = referenceCacheKey(scene, state, options);
    const std::filesystem::path file = std::filesystem::path(cacheDir) / (key + ".exr");
    std::error_code ec;
    if (std::filesystem::is_regular_file(file, ec)) {
        try {
            ReferenceImage img = readReferenceExr(file.string());
            if (img.key == key && img.width == state.width && img.height == state.height) {
                if (cacheHit) *cacheHit = true;
                return img;
            }
            logWarn("reference: cache file '" + file.string() + "' does not match its key; rendering again");
        } catch (const InputError& e) {
            logWarn(std::string("reference: unreadable cache file, rendering again: ") + e.what());
        }
    }
    ReferenceRenderer renderer(scene);
    ReferenceImage img = renderer.render(state, options);
    std::filesystem::create_directories(cacheDir, ec);
    try {
        writeReferenceExr(file.string(), img);
    } catch (const Error& e) {
        // The render itself is good: hand it back and say why it was not kept.
        logWarn(std::string("reference: could not cache the image: ") + e.what());
    }
    return img;
}

} // namespace gis

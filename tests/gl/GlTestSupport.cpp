#include "GlTestSupport.h"

#include <map>

#include <OpenImageIO/imageio.h>

#include "analysis/Metrics.h"
#include "frame/FrameState.h"
#include "frame/LightModel.h"

namespace gis::test {

gl::Context& sharedContext() {
    static std::unique_ptr<gl::Context> context = gl::createContext(gl::defaultBackend());
    context->makeCurrent();
    return *context;
}

FrameRenderer& sharedRenderer() {
    sharedContext();
    static std::unique_ptr<FrameRenderer> renderer = std::make_unique<FrameRenderer>();
    return *renderer;
}

FrameOutput renderScene(const std::string& sceneName, const std::string& technique, int w, int h,
                        const nlohmann::json& params, const std::function<void(FrameState&)>& edit) {
    sharedContext();
    static std::map<std::string, std::shared_ptr<Scene>> scenes;
    auto& scene = scenes[sceneName];
    if (!scene) scene = std::make_shared<Scene>(loadScene(sceneName));
    FrameRenderer* renderer = &sharedRenderer();
    if (renderer->scene() != scene.get()) renderer->setScene(scene);
    FrameState state = makeFrameState(*scene, technique);
    state.width = w;
    state.height = h;
    if (!params.is_null()) applyParams(state, params, "test"); // {} arrives as null
    if (edit) edit(state);
    return renderer->render(state, true);
}

FrameOutput renderScene(const Scene& scene, const std::string& technique, int w, int h,
                        const nlohmann::json& params, const std::function<void(FrameState&)>& edit,
                        bool wantDirect) {
    FrameRenderer& renderer = sharedRenderer();
    renderer.setScene(std::make_shared<const Scene>(scene));
    FrameState state = makeFrameState(scene, technique);
    state.width = w;
    state.height = h;
    if (!params.is_null()) applyParams(state, params, "test");
    if (edit) edit(state);
    return renderer.render(state, true, wantDirect);
}

IndirectPair indirectOnly(const FrameOutput& gl, const FrameOutput& glDirect, const std::vector<float>& ref,
                          const std::vector<float>& refDirect) {
    IndirectPair out;
    const size_t pixels = ref.size() / 3;
    out.gl.resize(ref.size());
    out.reference.resize(ref.size());
    for (size_t i = 0; i < pixels; ++i)
        for (size_t c = 0; c < 3; ++c) {
            out.gl[i * 3 + c] = gl.linear[i * 4 + c] - glDirect.linear[i * 4 + c];
            out.reference[i * 3 + c] = ref[i * 3 + c] - refDirect[i * 3 + c];
            out.glSum += out.gl[i * 3 + c];
            out.refSum += out.reference[i * 3 + c];
        }
    return out;
}

glm::ivec2 projectToPixel(const Scene& scene, glm::vec3 p, int w, int h) {
    glm::vec4 clip = cameraViewProj(scene.cameras.front(), w, h) * glm::vec4(p, 1.0f);
    glm::vec2 ndc = glm::vec2(clip) / clip.w;
    return {static_cast<int>((ndc.x * 0.5f + 0.5f) * w), static_cast<int>((0.5f - ndc.y * 0.5f) * h)};
}

double relativeRmseOf(const std::vector<float>& test, int testChannels, const std::vector<float>& reference,
                      int referenceChannels, std::size_t pixels) {
    const int n = static_cast<int>(pixels);
    return relativeRmse(
        ImageView{std::span<const float>(test.data(), pixels * testChannels), n, 1, testChannels},
        ImageView{std::span<const float>(reference.data(), pixels * referenceChannels), n, 1,
                  referenceChannels});
}

double relativeRmseOf(const FrameOutput& test, const FrameOutput& reference) {
    return relativeRmseOf(test.linear, 4, reference.linear, 4, reference.linear.size() / 4);
}

std::size_t badValues(const FrameOutput& f) {
    std::size_t bad = 0;
    for (float v : f.linear)
        if (!std::isfinite(v) || v < 0.0f) ++bad;
    return bad;
}

double counter(const FrameOutput& f, const std::string& name) {
    const auto& c = f.stats.at("counts");
    return c.contains(name) ? c.at(name).get<double>() : 0.0;
}

bool hasPass(const FrameOutput& f, const std::string& name) {
    for (const auto& p : f.stats.at("passes"))
        if (p.at("name") == name) return true;
    return false;
}

bool readPng(const std::string& path, int& w, int& h, std::vector<std::uint8_t>& rgb) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return false;
    const auto& spec = in->spec();
    w = spec.width;
    h = spec.height;
    rgb.resize(static_cast<size_t>(w) * h * 3);
    std::vector<std::uint8_t> all(static_cast<size_t>(w) * h * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, all.data())) return false;
    for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
        for (int c = 0; c < 3; ++c)
            rgb[i * 3 + c] = all[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
    return true;
}

bool writePng(const std::string& path, int w, int h, const std::vector<std::uint8_t>& rgba) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return false;
    OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::UINT8);
    return out->open(path, spec) && out->write_image(OIIO::TypeDesc::UINT8, rgba.data()) && out->close();
}

} // namespace gis::test

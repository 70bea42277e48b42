#include "job/ApiRender.h"

#include <string_view>

#include "core/Base64.h"
#include "core/Error.h"
#include "core/JsonSchema.h"
#include "frame/VplBudget.h"

namespace gis {
namespace {

std::string base64(const std::vector<std::uint8_t>& data) {
    return base64Encode(std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}

} // namespace

HttpReply jsonReply(unsigned status, const nlohmann::json& body) {
    return {status, "application/json", {}, body.dump()};
}

HttpReply errorReply(unsigned status, const std::string& code, const std::string& message,
                     const std::string& where) {
    nlohmann::json body = {{"error", code}, {"message", validUtf8(message)}};
    if (!where.empty()) body["where"] = validUtf8(where);
    return jsonReply(status, body);
}

ApiReplyForm takeReplyForm(nlohmann::json& request) {
    auto it = request.find("response");
    if (it == request.end()) return ApiReplyForm::Image;
    if (!it->is_string() || (*it != "image" && *it != "json"))
        throw InputError("/response", "must be \"image\" or \"json\"");
    const ApiReplyForm form = *it == "json" ? ApiReplyForm::Json : ApiReplyForm::Image;
    request.erase(it);
    return form;
}

HttpReply renderApiRequest(FrameRenderer& renderer, const RenderJob& job, const SceneResolver& resolve,
                           long maxVpls, double queueMs, ApiReplyForm form) {
    try {
        auto resolveAtScene = [&](const std::string& name) {
            try {
                return resolve(name);
            } catch (const InputError& e) {
                throw InputError("/scene", e.reason());
            }
        };
        const long vpls = vplEstimate(makeJobFrameState(*resolveAtScene(job.scene), job));
        if (vpls > maxVpls)
            throw InputError("/params", "these parameters ask for up to " + std::to_string(vpls) +
                                            " VPLs; the server allows " + std::to_string(maxVpls));
        RenderResult result = executeRenderJob(renderer, job, resolveAtScene);
        result.stats["queue_ms"] = queueMs;
        if (form == ApiReplyForm::Json) {
            nlohmann::json body = {{"stats", result.stats}, {"image_base64", base64(result.image)}};
            if (!result.referenceImage.empty()) body["reference_base64"] = base64(result.referenceImage);
            return jsonReply(200, body);
        }
        HttpReply r{200, result.mimeType, {{"x-gi-stats:", result.stats.dump()}}, {}};
        r.body.assign(result.image.begin(), result.image.end());
        return r;
    } catch (const InputError& e) {
        return errorReply(400, "invalid_request", e.reason(), e.where());
    } catch (const std::exception& e) {
        return errorReply(500, "render_failed", e.what());
    }
}

} // namespace gis

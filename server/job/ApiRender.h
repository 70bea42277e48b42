// POST /api/render's answer, without the socket: the reply a request gets (the encoded image with its
// stats in a header, or JSON with base64 images), the VPL cap that guards the service, and the
// error bodies every HTTP endpoint shares. The network layer (net/WsServer) only parses the HTTP
// request, queues this on a render worker and writes the reply back.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "job/RenderRequest.h"

namespace gis {

/// One HTTP reply.
struct HttpReply {
    unsigned status = 200;
    std::string contentType = "application/json";
    std::vector<std::pair<std::string, std::string>> headers; ///< ("x-gi-stats:", value): lws's header names
    std::string body;
};

HttpReply jsonReply(unsigned status, const nlohmann::json& body);
/// {"error": code, "message": message, "where": where (when given)}; the texts are made valid UTF-8
/// (they may quote the request's bytes).
HttpReply errorReply(unsigned status, const std::string& code, const std::string& message,
                     const std::string& where = {});

/// How the client wants the image: the encoded file itself (stats in X-GI-Stats) or JSON with
/// "stats", "image_base64" and, with compare, "reference_base64".
enum class ApiReplyForm { Image, Json };

/// Takes the API-only field "response" ("image" or "json") out of a request body. Throws
/// InputError("/response", ...) for another value.
ApiReplyForm takeReplyForm(nlohmann::json& request);

/// Renders `job` for the API on a render worker (the renderer's GL context current): refuses
/// parameters asking for more than `maxVpls` VPLs, resolves scenes through `resolve` (its
/// InputErrors answer at /scene), renders, and builds the reply with `queueMs` in the stats. Never
/// throws: bad requests become 400 invalid_request, failures 500 render_failed.
HttpReply renderApiRequest(FrameRenderer& renderer, const RenderJob& job, const SceneResolver& resolve,
                           long maxVpls, double queueMs, ApiReplyForm form);

} // namespace gis

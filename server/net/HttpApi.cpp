// The HTTP API of gi-server: the router (health, metrics, techniques, scenes, render, upload), static client
// files, responses written in two writable callbacks, render jobs handed to the workers and their answers
// delivered on the loop, and zipped uploads unpacked off the loop.
#include "net/ServerInternals.h"

namespace gis {

HttpExchange& WsServer::Impl::beginExchange(lws* wsi, PerSession* pss) {
    auto& owned = exchanges[wsi];
    owned = std::make_unique<HttpExchange>();
    pss->http = owned.get();
    return *owned;
}

void WsServer::Impl::endExchange(lws* wsi, PerSession* pss) {
    if (pss) pss->http = nullptr;
    exchanges.erase(wsi);
}

void WsServer::Impl::respond(lws* wsi, PerSession* pss, HttpResponse response) {
    if (!pss->http) beginExchange(wsi, pss);
    countHttp(pss->http->endpoint.empty() ? "static" : pss->http->endpoint, response.status);
    if (response.status >= 400 && response.status != 404)
        logRefusal("http_" + std::to_string(response.status), peerAddress(wsi) + " " +
                                                                  (pss->http->post ? "POST " : "GET ") +
                                                                  pss->http->uri.substr(0, 200));
    if (pss->http->post && !pss->http->bodyDone) {
        // Answered before its body came (auth, origin, limits): the body is not read, the
        // connection closes once the answer is out.
        pss->http->closeAfter = true;
        bodiesPending.erase(wsi);
        response.headers.emplace_back("connection:", "close");
    }
    pss->http->response = std::move(response);
    pss->http->ready = true;
    lws_callback_on_writable(wsi);
}

int WsServer::Impl::writeHttp(lws* wsi, PerSession* pss) {
    HttpExchange* x = pss ? pss->http : nullptr;
    if (!x || !x->ready) return 0;
    HttpResponse& r = x->response;
    if (!x->headersSent) {
        std::size_t extra = 512 + r.contentType.size();
        for (const auto& [k, v] : r.headers) extra += k.size() + v.size() + 8;
        std::vector<unsigned char> buf(LWS_PRE + extra);
        unsigned char* start = buf.data() + LWS_PRE;
        unsigned char* p = start;
        unsigned char* end = buf.data() + buf.size() - 1;
        if (lws_add_http_common_headers(wsi, r.status, r.contentType.c_str(), r.body.size(), &p, end))
            return -1;
        for (const auto& [k, v] : r.headers)
            if (lws_add_http_header_by_name(wsi, reinterpret_cast<const unsigned char*>(k.c_str()),
                                            reinterpret_cast<const unsigned char*>(v.data()),
                                            static_cast<int>(v.size()), &p, end))
                return -1;
        if (lws_finalize_write_http_header(wsi, start, &p, end)) return -1;
        x->headersSent = true;
        lws_callback_on_writable(wsi);
        return 0;
    }
    std::vector<unsigned char> body(LWS_PRE + r.body.size());
    std::memcpy(body.data() + LWS_PRE, r.body.data(), r.body.size());
    const int n = lws_write(wsi, body.data() + LWS_PRE, r.body.size(), LWS_WRITE_HTTP_FINAL);
    const bool closeAfter = pss->http->closeAfter;
    endExchange(wsi, pss);
    if (n < 0 || closeAfter) return -1;
    return lws_http_transaction_completed(wsi) ? -1 : 0;
}

int WsServer::Impl::serveFile(lws* wsi, PerSession* pss, const std::string& uri) {
    std::string path = uri == "/" ? "/index.html" : uri;
    if (path.find("..") != std::string::npos || path.find('\\') != std::string::npos || path[0] != '/') {
        respond(wsi, pss, errorReply(400, "bad_path", "paths may not contain '..' or backslashes"));
        return 0;
    }
    char resolved[PATH_MAX];
    const std::string full = config.clientDir + path;
    if (!realpath(full.c_str(), resolved) || std::string(resolved).rfind(clientRoot + "/", 0) != 0) {
        respond(wsi, pss, errorReply(404, "not_found", "no such file: " + uri));
        return 0;
    }
    countHttp("static", 200);
    int n = lws_serve_http_file(wsi, resolved, mimeType(resolved).c_str(), nullptr, 0);
    if (n < 0 || (n > 0 && lws_http_transaction_completed(wsi))) return -1;
    return 0;
}

nlohmann::json WsServer::Impl::scenesJson() const {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& n : catalog->list()) list.push_back(n);
    return list;
}

int WsServer::Impl::onHttpRequest(lws* wsi, PerSession* pss, const std::string& uri) {
    const bool post = lws_hdr_total_length(wsi, WSI_TOKEN_POST_URI) > 0;
    beginExchange(wsi, pss);
    pss->http->uri = uri;
    pss->http->post = post;
    pss->http->endpoint =
        uri.rfind("/api/", 0) == 0 || uri == "/metrics" || uri == "/healthz" ? uri : "static";
    if (!post) {
        pss->http->bodyDone = true;
        settle(wsi); // a GET is complete with its headers
    } else {
        auto peer = peers.find(wsi);
        const Clock::time_point start =
            peer != peers.end() && peer->second.pending ? peer->second.opened : Clock::now();
        pss->http->deadline = start + std::chrono::seconds(config.requestTimeoutS);
        bodiesPending.insert(wsi);
    }
    if (uri == "/healthz") {
        // 503 while draining: readiness probes and load balancers stop sending new clients here.
        const bool draining = phase != Phase::Running;
        nlohmann::json body = {{"status", draining ? "draining" : "ok"},
                               {"sessions", sessions->size()},
                               {"renders_active", gate->active()},
                               {"renders_waiting", gate->waiting()},
                               {"teardowns_pending", reaper->pending()},
                               {"uptime_s", std::chrono::duration<double>(Clock::now() - started).count()}};
        if (draining)
            body["drain_remaining_s"] =
                std::max(0.0, std::chrono::duration<double>(drainDeadline - Clock::now()).count());
        respond(wsi, pss, jsonReply(draining ? 503 : 200, body));
        return 0;
    }
    const bool api = uri.rfind("/api/", 0) == 0 || uri == "/metrics";
    if (api && !originAllowed(wsi)) {
        respond(wsi, pss, errorReply(403, "forbidden_origin", "this origin may not use the API"));
        return 0;
    }
    if (api && !bearerOk(wsi)) {
        HttpResponse r = errorReply(401, "unauthorized", "send 'Authorization: Bearer <token>'");
        r.headers.emplace_back("www-authenticate:", "Bearer");
        respond(wsi, pss, std::move(r));
        return 0;
    }
    if (post) {
        // lws reads bodies by Content-Length only: a chunked body would never complete, and a
        // malformed length would wait forever.
        if (!header(wsi, WSI_TOKEN_HTTP_TRANSFER_ENCODING).empty()) {
            respond(wsi, pss,
                    errorReply(411, "length_required",
                               "send the body with a Content-Length header; chunked transfer "
                               "encoding is not accepted"));
            return 0;
        }
        const std::string length = header(wsi, WSI_TOKEN_HTTP_CONTENT_LENGTH);
        if (length.empty()) {
            respond(wsi, pss, errorReply(411, "length_required", "POST needs a Content-Length header"));
            return 0;
        }
        if (length.size() > 12 || length.find_first_not_of("0123456789") != std::string::npos) {
            respond(wsi, pss,
                    errorReply(400, "bad_content_length",
                               "Content-Length must be a non-negative decimal number, got '" +
                                   length.substr(0, 40) + "'"));
            return 0;
        }
        if (uri == "/api/render" && phase != Phase::Running) {
            HttpResponse r = errorReply(503, "shutting_down",
                                        "the server is shutting down; send the request to another instance");
            r.headers.emplace_back("retry-after:", "1");
            respond(wsi, pss, std::move(r));
            return 0;
        }
        if (uri == "/api/render") {
            pss->http->bodyLimit = kMaxRenderRequestBytes;
        } else if (uri == "/api/upload") {
            if (config.maxUploadMb == 0) {
                respond(wsi, pss, errorReply(403, "uploads_disabled", "this server does not accept uploads"));
                return 0;
            }
            pss->http->bodyLimit = static_cast<std::size_t>(config.maxUploadMb) << 20;
        } else {
            respond(wsi, pss, errorReply(404, "not_found", "no POST endpoint " + uri));
            return 0;
        }
        if (std::stoull(length) > pss->http->bodyLimit) {
            // Refused from its header: the body is not read.
            respond(wsi, pss,
                    errorReply(413, "too_large",
                               "the body of " + length + " bytes exceeds " +
                                   std::to_string(pss->http->bodyLimit) + " bytes for " + uri));
            return 0;
        }
        return 0; // the body follows (LWS_CALLBACK_HTTP_BODY)
    }
    if (uri == "/metrics") {
        updateGauges();
        respond(wsi, pss, {200, "text/plain; version=0.0.4; charset=utf-8", {}, metrics.render()});
        return 0;
    }
    if (uri == "/api/techniques") {
        respond(wsi, pss,
                jsonReply(200, {{"techniques", techniquesJson()},
                                {"frame_params_schema", frameParamTable().jsonSchema()}}));
        return 0;
    }
    if (uri == "/api/scenes") {
        respond(wsi, pss, jsonReply(200, {{"scenes", scenesJson()}}));
        return 0;
    }
    if (uri == "/api/render" || uri == "/api/upload") {
        HttpResponse r = errorReply(405, "method_not_allowed", uri + " takes POST");
        r.headers.emplace_back("allow:", "POST");
        respond(wsi, pss, std::move(r));
        return 0;
    }
    if (uri.rfind("/api/", 0) == 0) {
        respond(wsi, pss, errorReply(404, "not_found", "unknown API endpoint " + uri));
        return 0;
    }
    return serveFile(wsi, pss, uri);
}

void WsServer::Impl::onHttpBody(lws* wsi, PerSession* pss) {
    HttpExchange* x = pss->http;
    bodiesPending.erase(wsi);
    if (x) x->bodyDone = true;
    settle(wsi);
    if (!x || x->ready) return; // already answered (auth, origin): the body is ignored
    if (x->bodyTooLarge) {
        respond(wsi, pss,
                errorReply(413, "too_large",
                           "the body exceeds " + std::to_string(x->bodyLimit) + " bytes for " + x->uri));
        return;
    }
    if (x->uri == "/api/render")
        startRender(wsi, pss);
    else if (x->uri == "/api/upload")
        handleUpload(wsi, pss);
}

void WsServer::Impl::startRender(lws* wsi, PerSession* pss) {
    HttpExchange* x = pss->http;
    std::string parseError;
    nlohmann::json request = parseJsonExplained(x->body, parseError);
    if (request.is_discarded() || !request.is_object()) {
        respond(wsi, pss,
                errorReply(400, "invalid_json",
                           request.is_discarded()
                               ? "the body is not valid JSON: " + parseError
                               : "the body must be a JSON object such as {\"scene\": \"builtin:cornell\"} "
                                 "(see PROTOCOL.md)"));
        return;
    }
    ApiReplyForm form = ApiReplyForm::Image;
    RenderLimits limits;
    limits.maxWidth = config.session.limits.maxWidth;
    limits.maxHeight = config.session.limits.maxHeight;
    std::shared_ptr<RenderJob> job;
    try {
        form = takeReplyForm(request);
        job = std::make_shared<RenderJob>(parseRenderRequest(request, limits));
    } catch (const InputError& e) {
        respond(wsi, pss, errorReply(400, "invalid_request", e.reason(), e.where()));
        return;
    }
    const std::uint64_t id = nextJobId++;
    auto catalogRef = catalog;
    auto sceneCache = scenes;
    lws_context* ctx = context;
    auto finish = [this, id, ctx](HttpResponse r) {
        {
            std::lock_guard lock(doneMutex);
            done[id] = std::move(r);
        }
        lws_cancel_service(ctx);
    };
    const long maxVpls = config.session.limits.maxVpls;
    auto work = [job, form, catalogRef, sceneCache, finish, maxVpls](FrameRenderer& renderer,
                                                                     double queueMs) {
        auto resolve = [&](const std::string& name) {
            return sceneCache->get(catalogRef->resolve(name), catalogRef->loadOptions(name));
        };
        finish(renderApiRequest(renderer, *job, resolve, maxVpls, queueMs, form));
    };
    auto fail = [finish](const std::string& message) { finish(errorReply(500, "render_failed", message)); };
    if (!workers->submit(work, fail)) {
        HttpResponse r = errorReply(503, "busy", "every render slot and queue place is taken; retry shortly");
        r.headers.emplace_back("retry-after:", "1");
        respond(wsi, pss, std::move(r));
        return;
    }
    x->jobId = id;
    awaiting[id] = wsi;
}

void WsServer::Impl::storeArchive(lws* wsi, PerSession* pss, const SessionEntry& entry,
                                  const std::string& name, const fs::path& dir, std::uintmax_t room) {
    HttpExchange* x = pss->http;
    const std::uint64_t id = nextJobId++;
    lws_context* ctx = context;
    auto body = std::make_shared<const std::string>(std::move(x->body));
    x->body.clear();
    const std::string what = "net: session " + entry.session->id() + " stored upload:" + name + " (" +
                             std::to_string(body->size()) + " bytes, scene ";
    const std::string from = ") from " + peerAddress(wsi);
    const int budgetMb = config.maxSessionUploadsMb;
    unpacker->retire([this, id, ctx, body, name, dir, room, what, from, budgetMb] {
        const fs::path partial = dir / ("." + name + ".part");
        std::error_code ec;
        fs::remove_all(partial, ec);
        HttpResponse response;
        try {
            const std::string sceneFile =
                extractSceneArchive(*body, partial, ArchiveLimits{.maxBytes = room}, name);
            fs::remove_all(dir / name, ec);
            fs::rename(partial, dir / name, ec);
            if (ec) throw Error("cannot rename the extracted folder");
            logInfo(what + sceneFile + from);
            response =
                jsonReply(201, {{"scene", "upload:" + name}, {"bytes", body->size()}, {"file", sceneFile}});
        } catch (const ArchiveTooLarge& e) {
            response = errorReply(413, "uploads_full",
                                  e.reason() + " (what this session's upload budget of " +
                                      std::to_string(budgetMb) + " MiB has left)");
        } catch (const InputError& e) {
            response = errorReply(400, "bad_archive", e.reason());
        } catch (const std::exception&) {
            fs::remove_all(partial, ec);
            response = errorReply(500, "upload_failed", "cannot store the upload");
        }
        {
            std::lock_guard lock(doneMutex);
            done[id] = std::move(response);
        }
        lws_cancel_service(ctx);
    });
    x->jobId = id;
    awaiting[id] = wsi;
}

void WsServer::Impl::handleUpload(lws* wsi, PerSession* pss) {
    HttpExchange* x = pss->http;
    const std::string name = urlArg(wsi, "name=");
    try {
        SceneCatalog::checkUploadName(name);
    } catch (const InputError& e) {
        respond(wsi, pss, errorReply(400, "invalid_name", e.reason(), "name"));
        return;
    }
    const std::string token = customHeader(wsi, "x-gi-session:");
    const std::shared_ptr<SessionEntry> entry = sessions->byResumeToken(token);
    if (!entry) {
        respond(wsi, pss,
                errorReply(404, "unknown_session",
                           "send the resume token of a live session in the X-GI-Session header"));
        return;
    }
    const bool zipped = name.ends_with(".zip");
    if (zipped && !looksLikeZip(x->body)) {
        respond(wsi, pss, errorReply(400, "not_zip", "the body is not a zip archive"));
        return;
    }
    if (!zipped && (x->body.size() < 12 || x->body.compare(0, 4, "glTF") != 0)) {
        respond(wsi, pss, errorReply(400, "not_glb", "the body is not a binary glTF (.glb) file"));
        return;
    }
    std::error_code ec;
    const fs::path dir = entry->session->uploadDir();
    fs::create_directories(dir, ec);
    // The session's uploads together (a replaced file no longer counts) stay within the budget;
    // an archive counts as what it unpacks to.
    std::uintmax_t stored = 0;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        if (it.depth() == 0 && it->path().filename() == name) {
            it.disable_recursion_pending();
            continue;
        }
        if (it->is_regular_file(ec)) stored += it->file_size(ec);
    }
    const std::uintmax_t budget = static_cast<std::uintmax_t>(config.maxSessionUploadsMb) << 20;
    if (zipped) {
        storeArchive(wsi, pss, *entry, name, dir, budget > stored ? budget - stored : 0);
        return;
    }
    if (stored + x->body.size() > budget) {
        respond(wsi, pss,
                errorReply(413, "uploads_full",
                           "this session's uploads would take " +
                               std::to_string((stored + x->body.size()) >> 20) +
                               " MiB; a session may store " + std::to_string(config.maxSessionUploadsMb) +
                               " MiB: upload under an existing name to replace a file"));
        return;
    }
    // Written beside, then renamed: a scene load never sees half a file.
    const fs::path partial = dir / ("." + name + ".part");
    {
        std::ofstream out(partial, std::ios::binary | std::ios::trunc);
        out.write(x->body.data(), static_cast<std::streamsize>(x->body.size()));
        if (!out) ec = std::make_error_code(std::errc::io_error);
    }
    if (!ec) fs::rename(partial, dir / name, ec);
    if (ec) {
        fs::remove(partial, ec);
        respond(wsi, pss, errorReply(500, "upload_failed", "cannot store the upload"));
        return;
    }
    logInfo("net: session " + entry->session->id() + " stored upload:" + name + " (" +
            std::to_string(x->body.size()) + " bytes) from " + peerAddress(wsi));
    respond(wsi, pss, jsonReply(201, {{"scene", "upload:" + name}, {"bytes", x->body.size()}}));
}

int WsServer::Impl::onHttp(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len) {
    switch (reason) {
    case LWS_CALLBACK_HTTP: {
        if (!pss) return -1;
        std::string uri(static_cast<const char*>(in),
                        strnlen(static_cast<const char*>(in), len ? len : 4096));
        return onHttpRequest(wsi, pss, uri);
    }
    case LWS_CALLBACK_HTTP_BODY:
        if (pss && pss->http && !pss->http->ready && !pss->http->closeAfter) {
            HttpExchange* x = pss->http;
            if (x->body.size() + len > x->bodyLimit) {
                x->bodyTooLarge = true;
                x->body.clear();
            } else if (!x->bodyTooLarge) {
                x->body.append(static_cast<const char*>(in), len);
            }
        }
        return 0;
    case LWS_CALLBACK_HTTP_BODY_COMPLETION:
        if (pss) onHttpBody(wsi, pss);
        return 0;
    case LWS_CALLBACK_HTTP_WRITEABLE:
        return writeHttp(wsi, pss);
    case LWS_CALLBACK_HTTP_DROP_PROTOCOL:
    case LWS_CALLBACK_CLOSED_HTTP:
        bodiesPending.erase(wsi);
        if (pss && pss->http && pss->http->jobId) awaiting.erase(pss->http->jobId); // the result is discarded
        endExchange(wsi, pss);
        break;
    default:
        break;
    }
    return lws_callback_http_dummy(wsi, reason, pss, in, len);
}

void WsServer::Impl::deliverFinishedJobs() {
    std::map<std::uint64_t, HttpResponse> finished;
    {
        std::lock_guard lock(doneMutex);
        finished.swap(done);
    }
    for (auto& [id, response] : finished) {
        auto it = awaiting.find(id);
        if (it == awaiting.end()) continue; // the client left
        lws* wsi = it->second;
        awaiting.erase(it);
        auto* pss = static_cast<PerSession*>(lws_wsi_user(wsi));
        if (!pss || !pss->http) continue;
        pss->http->jobId = 0;
        respond(wsi, pss, std::move(response));
    }
}

} // namespace gis

// The sessions a server holds, without a socket in sight: their ids, the controller's resume token and
// the viewers' view token, which connection steers each (a pointer the network layer owns),
// the grace period of a dropped controller, the session cap, the viewer cap, and which sessions have
// expired. The stream endpoint (WsServer) asks it what a hello means and acts on the answer; tests
// drive it with a stand-in session type (tests/unit/net/SessionDirectoryTest.cpp).
//
// SessionT needs: std::string id() const, std::size_t viewerCount() const, double idleSeconds() const.
// ControllerT is only pointed to.
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "session/ProtocolMessages.h"

namespace gis {

/// A fresh secret: `prefix` then 32 hex digits from std::random_device.
std::string randomToken(const char* prefix);
/// Compares a presented secret with the expected one in time that depends only on the expected one's
/// length.
bool sameSecret(const std::string& presented, const std::string& expected);

template <typename SessionT, typename ControllerT> class SessionDirectory {
public:
    using Clock = std::chrono::steady_clock;

    struct Entry {
        std::shared_ptr<SessionT> session;
        std::string resumeToken, viewToken;
        ControllerT* controller = nullptr; ///< the steering connection; null while detached
        Clock::time_point detachedAt{};    ///< when the controller went; epoch when never detached
        bool ended = false;
    };
    using EntryPtr = std::shared_ptr<Entry>;

    struct Limits {
        int maxSessions = 8;
        std::size_t maxViewersPerSession = 16;
        std::chrono::seconds resumeGrace{30};
        double idleTimeoutS = 900;
    };

    /// What a hello asks for, decided: join as a viewer, resume, open a new session, or a refusal
    /// with the error to send and the close code.
    struct HelloDecision {
        enum class Kind { Viewer, Resume, Open, Refuse } kind = Kind::Refuse;
        EntryPtr entry; ///< Viewer and Resume
        ProtocolError refusal;
        int closeCode = 1008;
    };

    explicit SessionDirectory(Limits limits) : mLimits(limits) {}

    /// `view` and `resume` are the hello's tokens, when present (view wins, as in PROTOCOL.md).
    HelloDecision decide(const std::optional<std::string>& view,
                         const std::optional<std::string>& resume) const {
        HelloDecision d;
        if (view) {
            d.entry = find(*view, false);
            if (!d.entry) {
                d.refusal = {"unknown_view_token", "no live session has this view token", "/view", "hello"};
            } else if (d.entry->session->viewerCount() >= mLimits.maxViewersPerSession) {
                d.refusal = {"busy", "this session has its maximum of viewers", "", "hello"};
                d.closeCode = 1013;
            } else {
                d.kind = HelloDecision::Kind::Viewer;
            }
            return d;
        }
        if (resume) {
            d.entry = find(*resume, true);
            if (!d.entry) {
                d.refusal = {"resume_failed",
                             "the session has ended or the token is unknown; connect without resume",
                             "/resume", "hello"};
                return d;
            }
            d.kind = HelloDecision::Kind::Resume;
            return d;
        }
        if (static_cast<int>(mEntries.size()) >= mLimits.maxSessions) {
            d.refusal = {"busy",
                         "the server has reached its session limit (" + std::to_string(mLimits.maxSessions) +
                             "); try again later",
                         "", "hello"};
            d.closeCode = 1013;
            return d;
        }
        d.kind = HelloDecision::Kind::Open;
        return d;
    }

    /// The id the next opened session gets: "s1", "s2", ...
    std::string nextId() {
        // Not "s" + to_string(...): GCC 12 warns (-Wrestrict) on that concatenation once inlined.
        std::string id = std::to_string(mNextId++);
        id.insert(id.begin(), 's');
        return id;
    }

    /// Registers a session under its id with fresh resume and view tokens.
    EntryPtr add(std::shared_ptr<SessionT> session) {
        auto entry = std::make_shared<Entry>();
        entry->resumeToken = randomToken("r-");
        entry->viewToken = randomToken("v-");
        entry->session = std::move(session);
        mEntries[entry->session->id()] = entry;
        return entry;
    }

    /// `controller` steers the entry from now on (the previous one, if any, is the caller's to close).
    void attach(Entry& entry, ControllerT* controller) {
        entry.controller = controller;
        entry.detachedAt = {};
    }
    /// The controller left at `now`: the grace period starts.
    void detach(Entry& entry, Clock::time_point now) {
        entry.controller = nullptr;
        entry.detachedAt = now;
    }

    /// Marks the entry ended and forgets it; false when it had ended already.
    bool end(Entry& entry) {
        if (entry.ended) return false;
        entry.ended = true;
        mEntries.erase(entry.session->id());
        return true;
    }

    struct Expiry {
        EntryPtr entry;
        std::string code;    ///< session_ended (grace period over) or idle_timeout
        std::string message; ///< for the clients
    };
    /// Sessions whose controller stayed away past the grace period, or that had no steering input
    /// for the idle timeout, at `now`.
    std::vector<Expiry> expired(Clock::time_point now) const {
        std::vector<Expiry> out;
        for (const auto& [id, e] : mEntries) {
            if (!e->controller && e->detachedAt != Clock::time_point{} &&
                now - e->detachedAt > mLimits.resumeGrace)
                out.push_back({e, "session_ended",
                               "the controller did not come back within " +
                                   std::to_string(mLimits.resumeGrace.count()) + " s"});
            else if (e->session->idleSeconds() > mLimits.idleTimeoutS)
                out.push_back({e, "idle_timeout",
                               "no steering input for " +
                                   std::to_string(static_cast<long>(mLimits.idleTimeoutS)) + " s"});
        }
        return out;
    }

    /// Entries without a controller (a draining server ends them: no resume can come).
    std::vector<EntryPtr> detached() const {
        std::vector<EntryPtr> out;
        for (const auto& [id, e] : mEntries)
            if (!e->controller) out.push_back(e);
        return out;
    }

    /// Every entry, by id (a copy: callers may end entries while they walk it).
    std::vector<EntryPtr> all() const {
        std::vector<EntryPtr> out;
        for (const auto& [id, e] : mEntries) out.push_back(e);
        return out;
    }
    /// The live session whose resume token this is (uploads name their session by it), or null.
    EntryPtr byResumeToken(const std::string& token) const {
        return token.empty() ? nullptr : find(token, true);
    }
    std::size_t size() const { return mEntries.size(); }
    bool empty() const { return mEntries.empty(); }

private:
    EntryPtr find(const std::string& token, bool resume) const {
        for (const auto& [id, e] : mEntries)
            if (sameSecret(token, resume ? e->resumeToken : e->viewToken)) return e;
        return nullptr;
    }

    Limits mLimits;
    std::map<std::string, EntryPtr> mEntries; // by session id
    std::uint64_t mNextId = 1;
};

} // namespace gis

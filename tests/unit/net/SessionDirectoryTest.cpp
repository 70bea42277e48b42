// The session directory decides what a hello means and when a session expires, with no socket and no
// renderer: a stand-in session type answers its id, viewers and idle time.
#include <gtest/gtest.h>

#include "net/SessionDirectory.h"

namespace gis {
namespace {

struct FakeSession {
    std::string name;
    std::size_t viewers = 0;
    double idle = 0;
    std::string id() const { return name; }
    std::size_t viewerCount() const { return viewers; }
    double idleSeconds() const { return idle; }
};
struct FakeConnection {};

using Directory = SessionDirectory<FakeSession, FakeConnection>;
using Kind = Directory::HelloDecision::Kind;
using Clock = Directory::Clock;

Directory::Limits limits() {
    return {.maxSessions = 2,
            .maxViewersPerSession = 1,
            .resumeGrace = std::chrono::seconds(30),
            .idleTimeoutS = 900};
}

std::shared_ptr<FakeSession> session(Directory& d) {
    return std::make_shared<FakeSession>(FakeSession{d.nextId()});
}

TEST(SessionDirectory, OpensUpToTheCapWithFreshTokens) {
    Directory d(limits());
    EXPECT_EQ(d.decide(std::nullopt, std::nullopt).kind, Kind::Open);
    auto a = d.add(session(d));
    auto b = d.add(session(d));
    EXPECT_EQ(a->session->id(), "s1");
    EXPECT_EQ(b->session->id(), "s2");
    EXPECT_TRUE(a->resumeToken.starts_with("r-") && a->resumeToken.size() == 34) << a->resumeToken;
    EXPECT_TRUE(a->viewToken.starts_with("v-"));
    EXPECT_NE(a->resumeToken, b->resumeToken);
    const auto full = d.decide(std::nullopt, std::nullopt);
    EXPECT_EQ(full.kind, Kind::Refuse);
    EXPECT_EQ(full.refusal.code, "busy");
    EXPECT_EQ(full.closeCode, 1013);
    EXPECT_NE(full.refusal.message.find("session limit (2)"), std::string::npos);
    EXPECT_TRUE(d.end(*a));
    EXPECT_FALSE(d.end(*a)) << "ending twice is a no-op";
    EXPECT_EQ(d.size(), 1u);
    EXPECT_EQ(d.decide(std::nullopt, std::nullopt).kind, Kind::Open) << "an ended session frees its place";
}

TEST(SessionDirectory, ResumeAndViewTokensFindTheirSessionOnly) {
    Directory d(limits());
    auto a = d.add(session(d));
    auto b = d.add(session(d));
    const auto resume = d.decide(std::nullopt, b->resumeToken);
    EXPECT_EQ(resume.kind, Kind::Resume);
    EXPECT_EQ(resume.entry, b);
    EXPECT_EQ(d.decide(std::nullopt, b->viewToken).kind, Kind::Refuse) << "a view token does not resume";
    const auto view = d.decide(a->viewToken, std::nullopt);
    EXPECT_EQ(view.kind, Kind::Viewer);
    EXPECT_EQ(view.entry, a);
    EXPECT_EQ(d.decide(a->viewToken, b->resumeToken).kind, Kind::Viewer) << "view wins over resume";
    std::string longer = a->resumeToken;
    longer.push_back('0');
    const auto unknown = d.decide(std::nullopt, longer);
    EXPECT_EQ(unknown.refusal.code, "resume_failed");
    EXPECT_EQ(unknown.closeCode, 1008);
    EXPECT_EQ(d.decide(std::string("v-nope"), std::nullopt).refusal.code, "unknown_view_token");
    EXPECT_EQ(d.byResumeToken(b->resumeToken), b);
    EXPECT_EQ(d.byResumeToken(""), nullptr);
    d.end(*b);
    EXPECT_EQ(d.decide(std::nullopt, b->resumeToken).refusal.code, "resume_failed") << "an ended session";
}

TEST(SessionDirectory, ViewersAreCappedPerSession) {
    Directory d(limits());
    auto a = d.add(session(d));
    a->session->viewers = 1;
    const auto full = d.decide(a->viewToken, std::nullopt);
    EXPECT_EQ(full.kind, Kind::Refuse);
    EXPECT_EQ(full.refusal.code, "busy");
    EXPECT_EQ(full.closeCode, 1013);
}

TEST(SessionDirectory, DetachedSessionsExpireAfterTheGraceIdleOnesAfterTheTimeout) {
    Directory d(limits());
    FakeConnection controller;
    auto a = d.add(session(d));
    auto b = d.add(session(d));
    d.attach(*a, &controller);
    d.attach(*b, &controller);
    const Clock::time_point t0 = Clock::now();
    EXPECT_TRUE(d.expired(t0 + std::chrono::hours(1)).empty()) << "attached and active: never";
    EXPECT_TRUE(d.detached().empty());

    d.detach(*a, t0);
    EXPECT_EQ(d.detached(), std::vector<Directory::EntryPtr>{a});
    EXPECT_TRUE(d.expired(t0 + std::chrono::seconds(30)).empty()) << "within the grace period";
    auto late = d.expired(t0 + std::chrono::seconds(31));
    ASSERT_EQ(late.size(), 1u);
    EXPECT_EQ(late[0].entry, a);
    EXPECT_EQ(late[0].code, "session_ended");
    EXPECT_EQ(late[0].message, "the controller did not come back within 30 s");

    d.attach(*a, &controller);
    EXPECT_TRUE(d.expired(t0 + std::chrono::seconds(31)).empty()) << "a resume ends the grace period";

    b->session->idle = 901;
    auto idle = d.expired(t0);
    ASSERT_EQ(idle.size(), 1u);
    EXPECT_EQ(idle[0].entry, b);
    EXPECT_EQ(idle[0].code, "idle_timeout");
    EXPECT_EQ(idle[0].message, "no steering input for 900 s");
}

TEST(SessionDirectory, SecretsCompareWhole) {
    EXPECT_TRUE(sameSecret("r-abc", "r-abc"));
    EXPECT_FALSE(sameSecret("r-ab", "r-abc"));
    EXPECT_FALSE(sameSecret("r-abcd", "r-abc"));
    EXPECT_FALSE(sameSecret("", "r-abc"));
    EXPECT_FALSE(sameSecret("r-abd", "r-abc"));
}

} // namespace
} // namespace gis

// Parameter extremes through gi-render (issue #10, "bad input"; tests/robustness/README.md). The cases
// come from the parameter tables (frameParamTable() and each technique's info().params), never from a
// hand-written list:
//   - every out-of-range or malformed value of every parameter of every technique is rejected by the
//     function gi-render's --param calls (setParamFromString), with a message that names the
//     parameter, the value and the range; a sample of them (one per kind of bad value) also through
//     the gi-render process: exit code 2 and the same message on stderr;
//   - in-range extremes render through gi-render into EXR (linear radiance) without NaN, Inf or
//     negative values: per technique, the parameters assigned to it round-robin, all at their minimum
//     in one frame; the maxima and every enum option go through the HTTP API and the WebSocket
//     (tests/e2e/robustness.test.mjs), where a render costs no process start;
//   - odd sizes at full resolution (1023x767 for `none` and `multires_gather`, 17x19, 16x4096) and sizes
//   below
//     the CLI's minimum (1x1, 3x2: a clear error naming --size and its range).
#include <gtest/gtest.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <sys/wait.h>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "core/Error.h"
#include "core/Param.h"
#include "gi/Technique.h"
#include "frame/FrameParams.h"
#include "frame/FrameState.h"
#include "scene/SceneLoader.h"

namespace {

namespace fs = std::filesystem;

// ---- cases derived from the tables --------------------------------------------------------------------

struct BadValue {
    std::string kind;
    std::string text;  ///< as typed after --param NAME=
    std::string shows; ///< what the error must quote after "got "
};

std::string number(double v) {
    if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    return ec == std::errc() ? std::string(buf, end) : std::to_string(v);
}

std::vector<BadValue> badValues(const gis::ParamSpec& s) {
    std::vector<BadValue> out;
    switch (s.type) {
    case gis::ParamType::Int:
    case gis::ParamType::Float:
        out.push_back({"below minimum", number(s.min - 1), number(s.min - 1)});
        out.push_back({"above maximum", number(s.max + 1), number(s.max + 1)});
        if (s.type == gis::ParamType::Int)
            out.push_back({"not an integer", number(s.min + 0.5), number(s.min + 0.5)});
        out.push_back({"NaN", "nan", "NaN"});
        out.push_back({"infinity", "inf", "Infinity"});
        out.push_back({"-infinity", "-inf", "-Infinity"});
        out.push_back({"not a number", "abc", "\"abc\""});
        out.push_back({"empty", "", "\"\""});
        break;
    case gis::ParamType::Enum:
        out.push_back({"unknown option", "no_such_option", "'no_such_option'"});
        out.push_back({"empty", "", "''"});
        break;
    case gis::ParamType::Bool:
        out.push_back({"not a boolean", "maybe", "\"maybe\""});
        break;
    }
    return out;
}

/// The message must say what (the parameter, the value) and how to fix it (type, range, unit or options).
void expectParamMessage(const std::string& message, const gis::ParamSpec& s, const BadValue& bad,
                        const std::string& what) {
    EXPECT_NE(message.find("'" + s.name + "'"), std::string::npos)
        << what << ": names the parameter: " << message;
    EXPECT_NE(message.find("got " + bad.shows), std::string::npos)
        << what << ": quotes the value (got " << bad.shows << "): " << message;
    switch (s.type) {
    case gis::ParamType::Int:
    case gis::ParamType::Float: {
        const std::string range = "[" + number(s.min) + ", " + number(s.max) + "]";
        EXPECT_NE(message.find(range), std::string::npos)
            << what << ": gives the range " << range << ": " << message;
        EXPECT_EQ(message.find("e+"), std::string::npos) << what << ": no rounded exponent form: " << message;
        if (!s.unit.empty()) {
            EXPECT_NE(message.find(s.unit), std::string::npos) << what << ": unit: " << message;
        }
        break;
    }
    case gis::ParamType::Enum:
        for (const auto& o : s.options)
            EXPECT_NE(message.find("'" + o + "'"), std::string::npos)
                << what << ": lists '" << o << "': " << message;
        break;
    case gis::ParamType::Bool:
        EXPECT_NE(message.find("true or false"), std::string::npos) << what << ": " << message;
        break;
    }
}

struct Owned {
    std::string technique;
    const gis::ParamSpec* spec;
};

/// Every parameter (frame and technique) of every technique.
std::vector<Owned> allParams() {
    std::vector<Owned> out;
    for (const auto& e : gis::techniqueRegistry()) {
        for (const auto& s : gis::frameParamTable().specs()) out.push_back({e.info.name, &s});
        for (const auto& s : e.info.params.specs()) out.push_back({e.info.name, &s});
    }
    return out;
}

/// Each parameter name once, with one technique that has it; the owners take turns (round-robin in the
/// order the names first appear), as in tests/e2e/robustness.test.mjs.
std::vector<Owned> sampledParams() {
    std::vector<std::string> order;
    std::map<std::string, std::vector<Owned>> owners;
    for (const auto& p : allParams()) {
        if (!owners.count(p.spec->name)) order.push_back(p.spec->name);
        owners[p.spec->name].push_back(p);
    }
    std::vector<Owned> out;
    for (size_t i = 0; i < order.size(); ++i) {
        const auto& list = owners[order[i]];
        // A VPL count's maximum costs ~40 s a frame in the splatting technique: its first owner renders it.
        const bool costly = list.front().spec->unit.find("VPL") != std::string::npos;
        out.push_back(list[costly ? 0 : i % list.size()]);
    }
    return out;
}

// ---- running gi-render ---------------------------------------------------------------------------------

struct ProcessResult {
    int code = -1;
    std::string output; ///< stdout and stderr
};

std::string quote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

ProcessResult runRender(const std::vector<std::string>& args) {
    std::string cmd = quote(GIS_RENDER_BIN);
    for (const auto& a : args) cmd += " " + quote(a);
    cmd += " 2>&1";
    ProcessResult r;
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buf{};
    size_t n = 0;
    while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
    const int status = pclose(pipe);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    return r;
}

fs::path workDir() {
    fs::path dir = fs::path(GIS_ROBUSTNESS_OUT_DIR) / "robustness_cli";
    fs::create_directories(dir);
    return dir;
}

struct LinearCheck {
    int width = 0, height = 0;
    long nonFinite = 0, negative = 0;
    double maxValue = 0, sum = 0;
};

LinearCheck readExr(const fs::path& path) {
    LinearCheck c;
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) {
        ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
        return c;
    }
    const OIIO::ImageSpec& spec = in->spec();
    c.width = spec.width;
    c.height = spec.height;
    std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    for (size_t i = 0; i < pixels.size(); ++i) {
        if (static_cast<int>(i % spec.nchannels) >= 3) continue; // alpha
        const float v = pixels[i];
        if (!std::isfinite(v))
            ++c.nonFinite;
        else if (v < 0)
            ++c.negative;
        else {
            c.maxValue = std::max(c.maxValue, static_cast<double>(v));
            c.sum += v;
        }
    }
    return c;
}

void expectSaneExr(const fs::path& path, int width, int height, const std::string& what) {
    const LinearCheck c = readExr(path);
    EXPECT_EQ(c.width, width) << what;
    EXPECT_EQ(c.height, height) << what;
    EXPECT_EQ(c.nonFinite, 0) << what << ": NaN/Inf in the linear output";
    EXPECT_EQ(c.negative, 0) << what << ": negative radiance in the linear output";
}

// ---- in-process: the CLI's own parser, exhaustive ---------------------------------------------------

TEST(RobustnessCli, EveryBadValueOfEveryParameterIsRejectedClearly) {
    const gis::Scene scene = gis::loadScene("builtin:cornell");
    int cases = 0;
    for (const auto& e : gis::techniqueRegistry()) {
        gis::FrameState state = gis::makeFrameState(scene, e.info.name);
        std::vector<const gis::ParamSpec*> specs;
        for (const auto& s : gis::frameParamTable().specs()) specs.push_back(&s);
        for (const auto& s : e.info.params.specs()) specs.push_back(&s);
        for (const gis::ParamSpec* s : specs) {
            for (const auto& bad : badValues(*s)) {
                const std::string what =
                    e.info.name + " --param " + s->name + "=" + bad.text + " (" + bad.kind + ")";
                try {
                    gis::setParamFromString(state, s->name, bad.text, "--param " + s->name);
                    ADD_FAILURE() << what << ": accepted";
                } catch (const gis::InputError& err) {
                    expectParamMessage(err.what(), *s, bad, what);
                }
                ++cases;
            }
        }
        try {
            gis::setParamFromString(state, "no_such_param", "1", "--param no_such_param");
            ADD_FAILURE() << e.info.name << ": unknown parameter accepted";
        } catch (const gis::InputError& err) {
            const std::string m = err.what();
            EXPECT_NE(m.find("unknown parameter 'no_such_param'"), std::string::npos) << m;
            if (!e.info.params.empty()) {
                EXPECT_NE(m.find(e.info.params.specs().front().name), std::string::npos)
                    << "lists the known: " << m;
            }
        }
    }
    EXPECT_GT(cases, 500);
}

// ---- the gi-render process -----------------------------------------------------------------------------

TEST(RobustnessCli, ProcessRejectsOneOfEachKindWithExitCode2) {
    // One launch per kind of bad value (a process start costs about 0.6 s here); the parameter for each
    // kind rotates through the table so that different parameters are hit.
    std::map<std::string, std::vector<Owned>> byKind;
    for (const auto& p : allParams())
        for (const auto& bad : badValues(*p.spec)) byKind[bad.kind].push_back(p);
    int i = 0;
    for (const auto& [kind, owners] : byKind) {
        const Owned& p = owners[(static_cast<size_t>(i++) * 7919) % owners.size()];
        BadValue bad;
        for (const auto& b : badValues(*p.spec))
            if (b.kind == kind) bad = b;
        const std::string what =
            "gi-render --technique " + p.technique + " --param " + p.spec->name + "=" + bad.text;
        const ProcessResult r =
            runRender({"--technique", p.technique, "--param", p.spec->name + "=" + bad.text, "--size",
                       "16x16", "--out", (workDir() / "never.exr").string()});
        EXPECT_EQ(r.code, 2) << what << "\n" << r.output;
        EXPECT_NE(r.output.find("--param " + p.spec->name), std::string::npos)
            << what << ": names the flag: " << r.output;
        expectParamMessage(r.output, *p.spec, bad, what);
    }
    const ProcessResult unknown = runRender({"--technique", "none", "--param", "no_such_param=1"});
    EXPECT_EQ(unknown.code, 2);
    EXPECT_NE(unknown.output.find("unknown parameter 'no_such_param' for technique 'none'"),
              std::string::npos)
        << unknown.output;
}

TEST(RobustnessCli, MinimumExtremesRenderWithoutNan) {
    // Per technique: the parameters assigned to it (sampledParams) all at their minimum (booleans false,
    // enums their first option) in one 16x16 frame; the linear EXR must be finite and non-negative.
    std::map<std::string, std::vector<std::string>> perTechnique;
    for (const auto& p : sampledParams()) {
        const gis::ParamSpec& s = *p.spec;
        std::string v;
        switch (s.type) {
        case gis::ParamType::Int:
        case gis::ParamType::Float:
            v = number(s.min);
            break;
        case gis::ParamType::Enum:
            v = s.options.front();
            break;
        case gis::ParamType::Bool:
            v = "false";
            break;
        }
        perTechnique[p.technique].push_back(s.name + "=" + v);
    }
    for (const auto& e : gis::techniqueRegistry()) {
        std::vector<std::string> args = {"--technique", e.info.name, "--size", "16x16", "--quiet"};
        for (const auto& kv : perTechnique[e.info.name]) {
            args.push_back("--param");
            args.push_back(kv);
        }
        const fs::path out = workDir() / ("min_" + e.info.name + ".exr");
        fs::remove(out);
        args.push_back("--out");
        args.push_back(out.string());
        std::string what = "gi-render";
        for (const auto& a : args) what += " " + a;
        const ProcessResult r = runRender(args);
        ASSERT_EQ(r.code, 0) << what << "\n" << r.output;
        expectSaneExr(out, 16, 16, what);
    }
}

TEST(RobustnessCli, OddResolutionsAtFullSize) {
    struct Case {
        std::string technique;
        int width, height;
    };
    const Case cases[] = {
        {"none", 1023, 767}, {"multires_gather", 1023, 767}, {"multires_gather", 17, 19}, {"none", 16, 4096}};
    for (const auto& c : cases) {
        const std::string size = std::to_string(c.width) + "x" + std::to_string(c.height);
        const fs::path out = workDir() / ("odd_" + c.technique + "_" + size + ".exr");
        fs::remove(out);
        std::vector<std::string> args = {"--technique", c.technique, "--size",    size,
                                         "--quiet",     "--out",     out.string()};
        if (c.technique != "none") args.insert(args.end(), {"--param", "vpl_grid=4"});
        const std::string what = "gi-render " + c.technique + " " + size;
        const ProcessResult r = runRender(args);
        ASSERT_EQ(r.code, 0) << what << "\n" << r.output;
        const LinearCheck lc = readExr(out);
        EXPECT_EQ(lc.width, c.width) << what;
        EXPECT_EQ(lc.height, c.height) << what;
        EXPECT_EQ(lc.nonFinite, 0) << what;
        EXPECT_EQ(lc.negative, 0) << what;
        EXPECT_GT(lc.sum, 0) << what << ": the lit box is not black";
    }
    // Below the CLI's 16 px minimum: a clear error naming the flag and its range, before any GL.
    for (const char* size : {"1x1", "3x2", "16x15", "4097x16", "0x0", "-16x16", "16x"}) {
        const ProcessResult r =
            runRender({"--technique", "none", "--size", size, "--out", (workDir() / "never.exr").string()});
        EXPECT_EQ(r.code, 2) << size << "\n" << r.output;
        EXPECT_NE(r.output.find("--size"), std::string::npos) << size << ": " << r.output;
        EXPECT_NE(r.output.find("[16, 4096]"), std::string::npos)
            << size << ": gives the range: " << r.output;
    }
}

} // namespace

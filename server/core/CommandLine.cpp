#include "core/CommandLine.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace gis::cli {

long parseInteger(const std::string& who, const std::string& text, long lo, long hi) {
    try {
        std::size_t used = 0;
        const long v = std::stol(text, &used);
        if (used == text.size() && v >= lo && v <= hi) return v;
    } catch (...) {
    }
    throw InputError(who, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                              "], got '" + text + "'");
}

double parseNumber(const std::string& who, const std::string& text, double lo, double hi) {
    try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size() && std::isfinite(v) && v >= lo && v <= hi) return v;
    } catch (...) {
    }
    throw InputError(who, "must be a number in [" + numberText(lo) + ", " + numberText(hi) + "], got '" +
                              text + "'");
}

void parseSize(const std::string& who, const std::string& text, int maxSide, int& width, int& height) {
    const auto x = text.find('x');
    if (x == std::string::npos) throw InputError(who, "must look like 512x512, got '" + text + "'");
    width = static_cast<int>(parseInteger(who + " width", text.substr(0, x), 16, maxSide));
    height = static_cast<int>(parseInteger(who + " height", text.substr(x + 1), 16, maxSide));
}

std::vector<std::string> splitList(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

std::string joinList(const std::vector<std::string>& items, const char* separator) {
    std::string out;
    for (const auto& i : items) out += (out.empty() ? "" : separator) + i;
    return out;
}

std::string numberText(double value) {
    // Whole numbers in full (10000000, not 1e+07): help texts show ranges such as 0..10000000.
    if (std::isfinite(value) && std::abs(value) < 1e15 && value == std::floor(value))
        return std::to_string(static_cast<long long>(value));
    std::ostringstream s;
    s << value;
    return s.str();
}

std::string defaultCacheDir() {
    if (const char* d = std::getenv("GI_CACHE_DIR"); d && *d) return d;
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/gi-render";
    return "/tmp/gi-render-cache";
}

int runMain(const char* program, const std::function<int()>& run) {
    try {
        return run();
    } catch (const InputError& e) {
        std::fprintf(stderr, "%s: %s\n", program, e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", program, e.what());
        return 1;
    }
}

OptionTable& OptionTable::flag(std::string name, std::string help, std::function<void()> apply) {
    mOptions.push_back({std::move(name), "", std::move(help),
                        [apply = std::move(apply)](const std::string&) { apply(); }, false});
    return *this;
}

OptionTable& OptionTable::value(std::string name, std::string valueName, std::string help,
                                std::function<void(const std::string&)> apply) {
    mOptions.push_back({std::move(name), std::move(valueName), std::move(help), std::move(apply), true});
    return *this;
}

OptionTable& OptionTable::integer(std::string name, std::string valueName, std::string help, long lo, long hi,
                                  int& target) {
    help +=
        ", " + std::to_string(lo) + ".." + std::to_string(hi) + " (default " + std::to_string(target) + ")";
    auto apply = [name, lo, hi, &target](const std::string& v) {
        target = static_cast<int>(parseInteger(name, v, lo, hi));
    };
    return value(std::move(name), std::move(valueName), std::move(help), apply);
}

OptionTable& OptionTable::number(std::string name, std::string valueName, std::string help, double lo,
                                 double hi, double& target) {
    help += ", " + numberText(lo) + ".." + numberText(hi) + " (default " + numberText(target) + ")";
    auto apply = [name, lo, hi, &target](const std::string& v) { target = parseNumber(name, v, lo, hi); };
    return value(std::move(name), std::move(valueName), std::move(help), apply);
}

OptionTable& OptionTable::section(std::string title) {
    mOptions.push_back({"", "", std::move(title), nullptr, false});
    return *this;
}

namespace {

/// `text` wrapped at `width` columns, every line after the first indented by `indent` spaces.
std::string wrapped(const std::string& text, std::size_t indent, std::size_t width) {
    std::string out, line;
    std::size_t used = indent;
    std::istringstream words(text);
    for (std::string word; words >> word;) {
        if (!line.empty() && used + 1 + word.size() > width) {
            out += line + "\n" + std::string(indent, ' ');
            line.clear();
            used = indent;
        }
        if (!line.empty()) {
            line += ' ';
            ++used;
        }
        line += word;
        used += word.size();
    }
    return out + line;
}

} // namespace

std::string OptionTable::usage(int width) const {
    constexpr std::size_t kColumn = 24; // "  --caustic-min-roughness R" and longer go on their own line
    std::string out;
    for (const Option& o : mOptions) {
        if (!o.apply) {
            out += "\n" + o.help + "\n";
            continue;
        }
        std::string head = "  " + o.name + (o.valueName.empty() ? "" : " " + o.valueName);
        if (head.size() + 2 > kColumn)
            head += "\n" + std::string(kColumn, ' ');
        else
            head += std::string(kColumn - head.size(), ' ');
        out += head + wrapped(o.help, kColumn, static_cast<std::size_t>(width)) + "\n";
    }
    return out;
}

bool OptionTable::asksForHelp(const std::vector<std::string>& args) {
    return std::any_of(args.begin(), args.end(),
                       [](const std::string& a) { return a == "--help" || a == "-h"; });
}

bool OptionTable::has(const std::string& name) const {
    for (const Option& o : mOptions)
        if (o.apply && o.name == name) return true;
    return false;
}

void OptionTable::parse(const std::vector<std::string>& args) const {
    for (std::size_t i = 0; i < args.size(); ++i) {
        const Option* found = nullptr;
        for (const Option& o : mOptions)
            if (o.apply && o.name == args[i]) found = &o;
        if (!found) throw UsageError("unknown option '" + args[i] + "' (see --help)");
        if (!found->takesValue) {
            found->apply({});
            continue;
        }
        if (i + 1 >= args.size()) throw UsageError(args[i] + " needs a value (" + found->valueName + ")");
        found->apply(args[++i]);
    }
}

} // namespace gis::cli

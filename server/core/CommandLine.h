// What the three executables (gi-render, gi-server, gi-bench) share on their command lines: number and
// size parsing with the accepted range in the message, option tables declared once (flag, value,
// help, range, default) from which both --help and the parse come, and the one way main() turns
// errors into a message and an exit code (2 bad usage or input, 1 anything else).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/Error.h"

namespace gis::cli {

/// Bad command-line usage that is not about one flag's value: main prints it and exits 2.
class UsageError : public InputError {
public:
    explicit UsageError(const std::string& message) : InputError("", message) {}
};

/// An integer in [lo, hi]; throws InputError(who, "must be an integer in [lo, hi], got '...'").
long parseInteger(const std::string& who, const std::string& text, long lo, long hi);
/// A finite number in [lo, hi]; throws InputError(who, "must be a number in [lo, hi], got '...'").
double parseNumber(const std::string& who, const std::string& text, double lo, double hi);
/// "WxH" with each side in [16, maxSide]; throws InputError naming `who`.
void parseSize(const std::string& who, const std::string& text, int maxSide, int& width, int& height);
/// Comma-separated items, empty ones dropped.
std::vector<std::string> splitList(const std::string& text);
/// "a, b, c", for messages listing the valid choices.
std::string joinList(const std::vector<std::string>& items, const char* separator = ", ");
/// "0.5", "8192": a number as the help text shows it (no trailing zeros).
std::string numberText(double value);

/// Where references are cached: $GI_CACHE_DIR, else ~/.cache/gi-render, else /tmp/gi-render-cache.
std::string defaultCacheDir();

/// main()'s body: runs `run`, and for an exception prints "PROGRAM: message" on stderr and returns 2
/// (InputError: bad usage or input) or 1 (anything else).
int runMain(const char* program, const std::function<int()>& run);

/// A command's options, each declared once; usage() and parse() both read the table.
class OptionTable {
public:
    /// A flag without a value.
    OptionTable& flag(std::string name, std::string help, std::function<void()> apply);
    /// A flag with a value the callback parses (throwing InputError naming the flag).
    OptionTable& value(std::string name, std::string valueName, std::string help,
                       std::function<void(const std::string&)> apply);
    /// An integer flag; the help line gets ", lo..hi (default D)" from the range and `target`'s value.
    OptionTable& integer(std::string name, std::string valueName, std::string help, long lo, long hi,
                         int& target);
    /// A number flag; the help line gets ", lo..hi (default D)".
    OptionTable& number(std::string name, std::string valueName, std::string help, double lo, double hi,
                        double& target);
    /// A heading line between groups of options in usage().
    OptionTable& section(std::string title);

    /// The options' help: "  --flag VALUE   help", the help wrapped at `width` columns.
    std::string usage(int width = 100) const;
    /// Whether `args` hold --help or -h anywhere: help wins over everything else on the line.
    static bool asksForHelp(const std::vector<std::string>& args);
    /// Applies `args` in order. Unknown flags and missing values throw UsageError / InputError.
    void parse(const std::vector<std::string>& args) const;
    bool has(const std::string& name) const;

private:
    struct Option {
        std::string name, valueName, help;
        std::function<void(const std::string&)> apply; ///< null for a section heading
        bool takesValue = false;
    };
    std::vector<Option> mOptions;
};

} // namespace gis::cli

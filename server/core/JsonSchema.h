// A small JSON Schema validator for the subset the protocol's schemas use: type (string or list),
// enum, const, required, properties, additionalProperties (bool or schema), items, minItems,
// maxItems, minimum, maximum, exclusiveMinimum, exclusiveMaximum, minLength, maxLength.
// Debian 12 packages no C++ validator; the subset is enough for flat control messages, and
// tests/unit checks it against the shared vectors in protocol/vectors/.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace gis {

struct SchemaViolation {
    std::string pointer; ///< JSON pointer to the offending value, "" for the root
    std::string message; ///< what is wrong and what was expected
};

/// Returns the first violation found, or nullopt when `instance` conforms to `schema`.
std::optional<SchemaViolation> validateJson(const nlohmann::json& instance, const nlohmann::json& schema);

/// `text` with every byte that is not part of valid UTF-8 written as \xNN: safe to put into JSON
/// (nlohmann::json::dump throws on invalid UTF-8) when a message quotes the client's input.
std::string validUtf8(std::string_view text);

/// Deepest array/object nesting accepted from a client, an HTTP body or a settings file. Protocol
/// messages and render requests nest at most 4 deep; the limit leaves room for extras while keeping
/// every recursive walk (copy, dump, schema check) a few kilobytes of stack.
constexpr int kMaxJsonDepth = 64;

/// Byte offset of the first '[' or '{' (outside strings) that opens level `maxDepth + 1`, or nullopt
/// when `text` nests at most `maxDepth` deep. Linear, allocation-free and safe on any bytes: it runs
/// before a parser so that no recursive code ever sees a deep document.
std::optional<std::size_t> findExcessNesting(std::string_view text, int maxDepth);

/// A short, bounded rendering of `value` for error messages: at most `maxChars` bytes (cut on a UTF-8
/// boundary, "..." appended), containers shown at most three levels deep, whatever the value's size.
std::string jsonExcerpt(const nlohmann::json& value, std::size_t maxChars = 60);

/// Parses `text`; on failure returns a discarded value and sets `error` to why and where, e.g.
/// "number overflow parsing '1e400'" or "syntax error at line 1, column 12: ..." (nlohmann's text
/// without its "[json.exception...]" prefix), so that error replies can say what to fix. Documents
/// nesting deeper than `maxDepth` are refused before parsing ("nested deeper than 64 levels at byte
/// N").
nlohmann::json parseJsonExplained(std::string_view text, std::string& error, int maxDepth = kMaxJsonDepth);

} // namespace gis

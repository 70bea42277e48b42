// A small JSON Schema validator for the subset the protocol's schemas use: type (string or list),
// enum, const, required, properties, additionalProperties (bool or schema), items, minItems,
// maxItems, minimum, maximum, exclusiveMinimum, exclusiveMaximum, minLength, maxLength.
// Debian 12 packages no C++ validator; the subset is enough for flat control messages, and
// tests/unit checks it against the shared vectors in protocol/vectors/.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace gis {

struct SchemaViolation {
    std::string pointer; ///< JSON pointer to the offending value, "" for the root
    std::string message; ///< what is wrong and what was expected
};

/// Returns the first violation found, or nullopt when `instance` conforms to `schema`.
std::optional<SchemaViolation> validateJson(const nlohmann::json& instance, const nlohmann::json& schema);

} // namespace gis

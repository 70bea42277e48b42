// The wire contract of protocol/PROTOCOL.md on the C++ side: validation of client messages against
// the JSON Schemas in protocol/schema (embedded in the binary), the binary frame header, and
// builders for server messages.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "encode/Encoder.h"

namespace gis {

constexpr int kProtocolVersion = 2;
/// The oldest protocol a client may speak: protocol 1 has one light (flat `light` messages, the
/// state's `light`), which protocol 2 still accepts and reports (protocol/PROTOCOL.md).
constexpr int kOldestProtocolVersion = 1;
constexpr std::size_t kFrameHeaderSize = 16;

/// A request the server rejects; becomes an `error` message, the session survives.
struct ProtocolError {
    std::string code;    ///< invalid_json, invalid_message, unknown_type, invalid_param, ...
    std::string message; ///< what is wrong and how to fix it
    std::string where;   ///< JSON pointer into the message, may be empty
    std::string request; ///< the message type, when known
};

/// One row of protocol/messages.json's client table: a message a client may send, who may send it
/// and who answers it. Its schema is protocol/schema/<type>.json.
struct ClientMessageSpec {
    std::string type;
    bool viewers = false;    ///< a viewer may send it too (else: read_only)
    bool connection = false; ///< the stream endpoint answers it itself; else Session::apply
};

/// Every client message, from the embedded protocol/messages.json.
const std::vector<ClientMessageSpec>& clientMessages();
/// The row of `type`, or null for a type the protocol does not have.
const ClientMessageSpec* findClientMessage(std::string_view type);
/// The message types a client may send (one schema each in protocol/schema).
const std::vector<std::string>& clientMessageTypes();
/// The message types the server sends as text (one schema each in protocol/schema/server).
const std::vector<std::string>& serverMessageTypes();
/// Checks a message the server is about to send against protocol/schema/server/<type>.json: the
/// first violation ("/state/size: ..."), or an empty string when it conforms. For tests.
std::string checkServerMessage(const nlohmann::json& message);
/// Parses and validates one client text message. Returns the parsed object; throws ProtocolError.
nlohmann::json parseClientMessage(std::string_view text);

nlohmann::json errorMessage(const ProtocolError& e);

/// 16-byte header + payload, as documented.
std::vector<std::uint8_t> makeFrameMessage(std::uint32_t frameId, int width, int height, ImageCodec codec,
                                           const std::vector<std::uint8_t>& payload);

} // namespace gis

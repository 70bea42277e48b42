// libFuzzer target for the protocol parser: parseClientMessage() validates one client text message
// against protocol/schema and may only throw gis::ProtocolError (which the session turns into an
// `error` message); a crash, another exception or a sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "session/ProtocolMessages.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const nlohmann::json message = gis::parseClientMessage(text);
        (void)message.dump();
    } catch (const gis::ProtocolError& e) {
        (void)gis::errorMessage(e).dump();
    }
    return 0;
}

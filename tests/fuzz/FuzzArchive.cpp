// libFuzzer target for zipped uploads: the bytes are a .zip that extractSceneArchive() unpacks into a
// fresh folder (upload limits), and whose scene file, when it has one, loads as a zipped upload does
// (external files inside its folder only, the decoded-size budget). Only gis::InputError may leave
// either: any other exception, a crash, a sanitizer report or a file written outside the folder is a
// finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

#include "core/Error.h"
#include "scene/SceneArchive.h"
#include "scene/SceneLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace fs = std::filesystem;
    static const fs::path base = "/dev/shm/gis_fuzz_archive_" + std::to_string(::getpid());
    const fs::path dest = base / "upload.zip";
    std::error_code ec;
    fs::remove_all(base, ec);
    fs::create_directories(base, ec);
    try {
        const std::string bytes(reinterpret_cast<const char*>(data), size);
        const std::string scene =
            gis::extractSceneArchive(bytes, dest, gis::ArchiveLimits{.maxBytes = 64u << 20, .maxEntries = 256},
                                     "upload:fuzz.zip");
        gis::SceneLoadOptions options;
        options.displayName = "upload:fuzz.zip";
        options.maxDecodedBytes = std::uint64_t(512) << 20;
        (void)gis::loadScene((dest / scene).string(), options).triangleCount();
    } catch (const gis::InputError&) {
        // Refused with a message: the expected outcome for most inputs.
    }
    // Nothing may land beside the extraction folder.
    for (const auto& entry : fs::directory_iterator(base, ec))
        if (entry.path() != dest) std::abort();
    fs::remove_all(base, ec);
    return 0;
}

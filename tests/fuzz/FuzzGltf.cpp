// libFuzzer target for the scene loader: the bytes become a .glb (or, when they start with '{', a
// .gltf) file that loadScene() reads. A .glb takes the server's upload path (no external files, the
// default decoded-size budget of --max-decoded-mb, the client's name in errors); a .gltf the path of
// a scene-directory file (external files inside its folder only, same budget). The loader's contract (scene/SceneLoader.h) is that only
// gis::InputError leaves it: any other exception, a crash or a sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <unistd.h>

#include "core/Error.h"
#include "scene/SceneLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // One file per process (libFuzzer runs inputs one after another in a process); /dev/shm keeps
    // the write off the disk.
    static const std::string base = "/dev/shm/gis_fuzz_" + std::to_string(::getpid());
    const bool json = size > 0 && data[0] == '{';
    const std::string path = base + (json ? ".gltf" : ".glb");
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    if (size > 0) std::fwrite(data, 1, size, f);
    std::fclose(f);
    try {
        gis::SceneLoadOptions options;
        options.displayName = json ? "file:fuzz.gltf" : "upload:fuzz.glb";
        options.allowExternalFiles = json;
        options.maxDecodedBytes = std::uint64_t(512) << 20; // below the fuzzer's 2 GiB RSS limit
        const gis::Scene scene = gis::loadScene(path, options);
        (void)scene.triangleCount();
    } catch (const gis::InputError&) {
        // Rejected with a message: the expected outcome for most inputs.
    }
    std::remove(path.c_str());
    return 0;
}

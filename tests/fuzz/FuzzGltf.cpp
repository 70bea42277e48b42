// libFuzzer target for the scene loader: the bytes become a .glb (or, when they start with '{', a
// .gltf) file that loadScene() reads. The loader's contract (scene/SceneLoader.h) is that only
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
        const gis::Scene scene = gis::loadScene(path);
        (void)scene.triangleCount();
    } catch (const gis::InputError&) {
        // Rejected with a message: the expected outcome for most inputs.
    }
    std::remove(path.c_str());
    return 0;
}

#include "scene/SceneArchive.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <memory>
#include <vector>

#include <sys/stat.h>
#include <zip.h>

#include "core/Error.h"

namespace gis {
namespace fs = std::filesystem;
namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

bool isSceneName(const std::string& name) {
    const std::string l = lower(name);
    return l.ends_with(".gltf") || l.ends_with(".glb");
}

/// macOS Finder's resource forks and folder metadata, present in many zips made on a Mac.
bool isMacMetadata(const std::string& name) {
    if (name.starts_with("__MACOSX/")) return true;
    const std::size_t slash = name.find_last_of('/');
    const std::string base = slash == std::string::npos ? name : name.substr(slash + 1);
    return base.starts_with("._") || base == ".DS_Store";
}

/// An entry name that stays inside the folder: relative, '/'-separated, no '..', '.', empty or
/// backslash-carrying segments and no control characters.
bool safeEntryName(const std::string& name) {
    if (name.empty() || name.size() > 1024 || name[0] == '/') return false;
    if (name.find('\\') != std::string::npos || name.find(':') != std::string::npos) return false;
    for (unsigned char c : name)
        if (c < 0x20 || c == 0x7f) return false;
    std::size_t start = 0;
    while (start <= name.size()) {
        std::size_t end = name.find('/', start);
        if (end == std::string::npos) end = name.size();
        const std::string segment = name.substr(start, end - start);
        const bool lastOfDirectory = end == name.size() && segment.empty() && start > 0; // "dir/"
        if (!lastOfDirectory && (segment.empty() || segment == "." || segment == "..")) return false;
        start = end + 1;
    }
    return true;
}

[[noreturn]] void refuse(const std::string& displayName, const std::string& message) {
    throw InputError(displayName, message);
}

struct ZipCloser {
    void operator()(zip_t* z) const { zip_discard(z); }
};
struct ZipFileCloser {
    void operator()(zip_file_t* f) const { zip_fclose(f); }
};

} // namespace

bool looksLikeZip(const std::string& bytes) {
    return bytes.size() >= 4 && bytes[0] == 'P' && bytes[1] == 'K' &&
           ((bytes[2] == 3 && bytes[3] == 4) || (bytes[2] == 5 && bytes[3] == 6));
}

std::string extractSceneArchive(const std::string& bytes, const fs::path& dest, const ArchiveLimits& limits,
                                const std::string& displayName) {
    if (!looksLikeZip(bytes))
        refuse(displayName, "not a zip archive: upload a .zip holding a .gltf with its files, or a .glb");

    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
    if (!source) refuse(displayName, "cannot read the archive: " + std::string(zip_error_strerror(&error)));
    std::unique_ptr<zip_t, ZipCloser> archive(
        zip_open_from_source(source, ZIP_RDONLY | ZIP_CHECKCONS, &error));
    if (!archive) {
        zip_source_free(source);
        const std::string why = zip_error_strerror(&error);
        zip_error_fini(&error);
        refuse(displayName, "the zip archive is damaged (" + why + "): create it again");
    }
    zip_error_fini(&error);

    const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
    if (count < 0 || count > limits.maxEntries)
        refuse(displayName, "the archive has " + std::to_string(count) + " entries; at most " +
                                std::to_string(limits.maxEntries) +
                                " are accepted: zip only the scene and its files");

    std::error_code ec;
    if (fs::exists(dest, ec)) refuse(displayName, "internal: the extraction folder exists already");
    fs::create_directories(dest, ec);
    if (ec) throw Error("archive: cannot create the extraction folder: " + ec.message());
    std::vector<std::string> scenes;
    try {
        std::uint64_t total = 0;
        std::vector<char> buffer(1 << 16);
        for (zip_int64_t i = 0; i < count; ++i) {
            zip_stat_t st;
            zip_stat_init(&st);
            if (zip_stat_index(archive.get(), static_cast<zip_uint64_t>(i), 0, &st) != 0 ||
                !(st.valid & ZIP_STAT_NAME))
                refuse(displayName, "entry " + std::to_string(i) +
                                        " of the archive cannot be read: create the archive again");
            const std::string name = st.name;
            if (isMacMetadata(name)) continue;
            if (!safeEntryName(name))
                refuse(displayName, "entry '" + name +
                                        "' is not a plain relative path (absolute, '..' or backslashes): zip "
                                        "the scene's folder "
                                        "from inside it");
            if ((st.valid & ZIP_STAT_ENCRYPTION_METHOD) && st.encryption_method != ZIP_EM_NONE)
                refuse(displayName,
                       "entry '" + name + "' is encrypted: create the archive without a password");
            zip_uint8_t opsys = 0;
            zip_uint32_t attributes = 0;
            if (zip_file_get_external_attributes(archive.get(), static_cast<zip_uint64_t>(i), 0, &opsys,
                                                 &attributes) == 0 &&
                opsys == ZIP_OPSYS_UNIX && S_ISLNK(attributes >> 16))
                refuse(displayName, "entry '" + name + "' is a symbolic link: zip the files themselves");
            const fs::path target = dest / name;
            if (name.ends_with("/")) {
                fs::create_directories(target, ec);
                if (ec) refuse(displayName, "cannot create folder '" + name + "'");
                continue;
            }
            fs::create_directories(target.parent_path(), ec);
            if (ec || fs::exists(target, ec))
                refuse(displayName, "entry '" + name + "' clashes with another entry of the archive");
            std::unique_ptr<zip_file_t, ZipFileCloser> in(
                zip_fopen_index(archive.get(), static_cast<zip_uint64_t>(i), 0));
            if (!in)
                refuse(displayName,
                       "entry '" + name + "' cannot be opened: " + std::string(zip_strerror(archive.get())));
            std::ofstream out(target, std::ios::binary | std::ios::trunc);
            if (!out) throw Error("archive: cannot write an extracted file");
            for (;;) {
                const zip_int64_t got = zip_fread(in.get(), buffer.data(), buffer.size());
                if (got < 0) refuse(displayName, "entry '" + name + "' is damaged: create the archive again");
                if (got == 0) break;
                total += static_cast<std::uint64_t>(got);
                if (total > limits.maxBytes)
                    throw ArchiveTooLarge(displayName, "the archive unpacks to more than " +
                                                           std::to_string(limits.maxBytes >> 20) +
                                                           " MiB: compress the textures, or upload a .glb");
                out.write(buffer.data(), got);
            }
            if (!out) throw Error("archive: writing an extracted file failed (disk full?)");
            if (isSceneName(name)) scenes.push_back(name);
        }
        if (scenes.empty())
            refuse(displayName,
                   "the archive holds no .gltf or .glb file: zip the scene file together with its .bin and "
                   "textures");
        if (scenes.size() > 1) {
            std::sort(scenes.begin(), scenes.end());
            std::string list;
            for (const auto& s : scenes) list += (list.empty() ? "'" : ", '") + s + "'";
            refuse(displayName, "the archive holds " + std::to_string(scenes.size()) + " scene files (" +
                                    list + "): zip one scene at a time");
        }
    } catch (...) {
        fs::remove_all(dest, ec);
        throw;
    }
    return scenes.front();
}

std::optional<fs::path> findArchivedScene(const fs::path& dir) {
    std::error_code ec;
    std::optional<fs::path> found;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        const std::string rel = fs::relative(it->path(), dir, ec).generic_string();
        if (isMacMetadata(rel) || !it->is_regular_file(ec) || !isSceneName(rel)) continue;
        if (found) return std::nullopt; // extractSceneArchive never leaves two
        found = it->path();
    }
    return found;
}

} // namespace gis

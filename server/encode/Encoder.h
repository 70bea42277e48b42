// Frame encoding: JPEG through libjpeg-turbo (the streaming path), PNG through libpng (lossless
// stills), and image files (PNG, JPEG, EXR) through OpenImageIO.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace gis {

/// RGBA8 rows top to bottom -> JPEG (alpha dropped). quality in [1, 100]. Throws gis::Error.
std::vector<std::uint8_t> encodeJpeg(const std::uint8_t* rgba, int width, int height, int quality);
/// RGBA8 rows top to bottom -> PNG (RGB, alpha dropped: frames are opaque). Throws gis::Error.
std::vector<std::uint8_t> encodePng(const std::uint8_t* rgba, int width, int height);

/// Writes a tone-mapped RGBA8 image (.png, .jpg/.jpeg) or linear radiance (.exr, from `linear`,
/// RGBA float) chosen by the file extension. `metadata` pairs go into the file header where the
/// format supports it. Throws gis::InputError naming the path for unknown extensions or I/O errors.
void writeImageFile(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgba8,
                    const std::vector<float>& linear,
                    const std::vector<std::pair<std::string, std::string>>& metadata = {});

/// True when `path` ends in an extension writeImageFile needs linear data for (.exr).
bool imageFileNeedsLinear(const std::string& path);

} // namespace gis

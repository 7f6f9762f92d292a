// Image files: OpenEXR (any number of named float channels), PNG (tone-mapped 8-bit sRGB via
// libpng), JPEG (read only, via libjpeg) and PFM (little-endian, rows bottom to top). Writers go through a temporary file
// and a rename, so a failed write never leaves a half-written output behind.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/memory.h"

namespace wedge::io {

/// One named float channel of an EXR file; `data` has `stride` floats between pixels
/// (stride 3 picks one component out of an Image3f).
struct ExrChannel {
    std::string name;
    const float* data;
    int stride = 1;
};

void writeExr(const std::string& path, int width, int height, const std::vector<ExrChannel>& channels);

struct ExrImage {
    int width = 0, height = 0;
    /// Allocated unwritten (core/memory.h): the reader writes every float, and a file that
    /// ends early fails having touched only the lines it read, not the header's whole size.
    std::map<std::string, std::vector<float, UnwrittenAllocator<float>>> channels;
};
ExrImage readExr(const std::string& path);

/// Linear radiance -> 8-bit sRGB (clamped, exposure 1).
void writePng(const std::string& path, const Image3f& linear);
/// A single-channel image mapped to a perceptual colour ramp over [lo, hi] (debug maps).
void writePngHeat(const std::string& path, const Image1f& values, float lo, float hi);
Image3f readPng(const std::string& path);
/// An 8-bit JPEG (RGB or greyscale), decoded from sRGB to linear: texture maps.
Image3f readJpeg(const std::string& path);

void writePfm(const std::string& path, const Image3f& linear);
Image3f readPfm(const std::string& path);

/// Colour image by extension: .exr (R, G, B), .png (decoded to linear), .pfm.
Image3f readColor(const std::string& path);
/// Colour image by extension, without buffers (.exr gets R, G, B only).
void writeColor(const std::string& path, const Image3f& linear);

/// Lower-case extension with the dot, "" if none.
std::string extension(const std::string& path);
/// Throws wedge::Error unless `path` ends in one of `allowed` and its directory exists.
void checkOutputPath(const std::string& path, const std::vector<std::string>& allowed);

float srgbEncode(float linear);
float srgbDecode(float encoded);

}  // namespace wedge::io

#include "io/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/openexr.h>
#include <png.h>
#include <cstdio>  // before jpeglib.h, which needs FILE and size_t declared
#include <jpeglib.h>

#include <algorithm>
#include <atomic>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <unistd.h>

#include "core/error.h"
#include "core/memory_limit.h"
#include "core/parallel.h"
#include "io/output_file.h"
#include "io/text_file.h"

namespace fs = std::filesystem;

namespace wedge::io {

namespace {

/// The most pixels a read image may have: what wedge renders at most.
constexpr uint64_t kMaxImagePixels = uint64_t(kMaxImageSide) * kMaxImageSide;

/// Why a header's size is more than wedge reads, or "" if it is not. (Each side first: an EXR's
/// window can be 2^32 pixels on a side, whose product wraps to 0 in 64 bits.)
std::string oversize(const char* format, uint64_t w, uint64_t h) {
    if (w <= kMaxImagePixels && h <= kMaxImagePixels && w * h <= kMaxImagePixels) return "";
    return std::string("the ") + format + "'s header gives " + std::to_string(w) + "x" + std::to_string(h) +
           " pixels, more than wedge reads (" + std::to_string(kMaxImageSide) + "x" + std::to_string(kMaxImageSide) + ")";
}

/// Why decoding a w x h image (its rows as the file stores them, `fileBytes` a pixel, then an
/// Image3f) would exceed the memory limit (core/memory_limit.h), or "" if it would not.
std::string overMemory(const char* format, uint64_t w, uint64_t h, uint64_t fileBytes) {
    return overMemoryLimit(std::string("the ") + format + "'s " + std::to_string(w) + "x" + std::to_string(h) + " pixels",
                           w * h * (fileBytes + sizeof(Vec3f)));
}

}  // namespace

std::string extension(const std::string& path) {
    std::string e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

void checkOutputPath(const std::string& path, const std::vector<std::string>& allowed) {
    std::string e = extension(path);
    if (std::find(allowed.begin(), allowed.end(), e) == allowed.end()) {
        std::string list;
        for (auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        throw Error(path, "unsupported output format '" + e + "' (expected " + list + ")");
    }
    fs::path dir = fs::path(path).parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec)) throw Error(path, "output directory does not exist");
}

float srgbEncode(float v) {
    v = std::clamp(v, 0.f, 1.f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}
float srgbDecode(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

// --- EXR -------------------------------------------------------------------------------------

namespace {

/// OpenEXR compresses and decompresses blocks of lines on its own thread pool, which is empty
/// unless asked for: `wedge render -o x.exr` writes 65 float channels, and at 512x512 their ZIP
/// compression took 1.43 s on one thread, 0.79 s on two (as long as the 16-spp render itself).
/// The pool gets the hardware's threads once; a file uses as many as --threads allows.
int exrThreads() {
    static std::once_flag once;
    std::call_once(once, [] { Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency()))); });
    return std::max(1, ThreadLimit::current());
}

/// deflate's fastest level: 0.61 s instead of 0.79 s for those channels on two threads, and a
/// file 2% larger (27.7 MB against 27.1 MB; the default level 4 or 6 saves nothing more).
constexpr int kZipLevel = 1;

}  // namespace

void writeExr(const std::string& path, int width, int height, const std::vector<ExrChannel>& channels) {
    atomicWrite(path, [&](const std::string& tmp) {
        // Through a stream of wedge's own: OpenEXR writes the line offsets as its OutputFile
        // closes, and keeps a failure there (a full disk) to itself; the stream's state shows it.
        std::ofstream os(tmp, std::ios::binary);
        if (!os) throw Error(path, std::string("cannot open for writing: ") + std::strerror(errno));
        try {
            Imf::Header header(width, height);
            header.compression() = Imf::ZIP_COMPRESSION;
            header.zipCompressionLevel() = kZipLevel;
            Imf::FrameBuffer fb;
            for (const auto& c : channels) {
                header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
                fb.insert(c.name, Imf::Slice(Imf::FLOAT, (char*)c.data, sizeof(float) * c.stride,
                                             sizeof(float) * c.stride * size_t(width)));
            }
            Imf::StdOFStream stream(os, path.c_str());  // the name OpenEXR's messages give
            Imf::OutputFile file(stream, header, exrThreads());
            file.setFrameBuffer(fb);
            file.writePixels(height);
        } catch (const Error&) {
            throw;
        } catch (const std::exception& e) {
            throw Error(path, std::string("cannot write EXR: ") + e.what());
        }
        os.close();
        if (!os) throw Error(path, std::string("cannot write EXR: ") + std::strerror(errno));
    });
}

namespace {

/// The first error OpenEXRCore reports while it reads a header (its user data: a std::string).
void keepExrCoreError(exr_const_context_t ctxt, exr_result_t code, const char* message) {
    void* user = nullptr;
    if (exr_get_user_data(ctxt, &user) != EXR_ERR_SUCCESS || !user) return;
    auto& kept = *static_cast<std::string*>(user);
    if (kept.empty()) kept = message && *message ? message : exr_get_default_error_message(code);
}

/// Bytes of a pixel type as the file stores it.
uint64_t exrTypeBytes(exr_pixel_type_t t) { return t == EXR_PIXEL_HALF ? 2 : 4; }

/// Reads the header of `path` alone with OpenEXRCore (the C core of the library), which checks
/// every attribute's declared size against the file's size and the data window and tiles against
/// the largest wedge reads, and refuses what the C++ library would allocate past the memory limit
/// as it opens the file: it reads an attribute by allocating the size the header declares (2 GB
/// from a few bytes: what held fuzz_exr to 30 executions a second), and sizes its decoding buffers
/// from the header (two a thread, each a chunk of lines or a tile, and up to three times that
/// again in the decompressor's scratch) before reading a pixel. Returns the threads to open it
/// with: `threads` at most, fewer where the image has fewer chunks.
int checkExrHeader(const std::string& path, int threads) {
    std::string why;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keepExrCoreError;
    init.user_data = &why;
    init.max_image_width = init.max_image_height = kMaxImageSide;
    init.max_tile_width = init.max_tile_height = kMaxImageSide;
    exr_context_t ctxt = nullptr;
    const exr_result_t opened = exr_start_read(&ctxt, path.c_str(), &init);
    // Closes the context on every way out.
    std::unique_ptr<exr_context_t, void (*)(exr_context_t*)> closer(&ctxt, [](exr_context_t* c) {
        if (*c) exr_finish(c);
    });
    // An error it reports is a refusal even where it goes on: OpenEXRCore 3.1 reports an
    // attribute larger than the file, skips it and returns success.
    if (opened != EXR_ERR_SUCCESS || !why.empty()) {
        if (why.empty()) why = exr_get_default_error_message(opened);
        throw Error(path, "not a readable EXR file: " + why);
    }
    exr_storage_t storage = EXR_STORAGE_SCANLINE;
    exr_attr_box2i_t dw{};
    const exr_attr_chlist_t* channels = nullptr;
    if (exr_get_storage(ctxt, 0, &storage) != EXR_ERR_SUCCESS || exr_get_data_window(ctxt, 0, &dw) != EXR_ERR_SUCCESS ||
        exr_get_channels(ctxt, 0, &channels) != EXR_ERR_SUCCESS || !channels)
        throw Error(path, "not a readable EXR file: " + (why.empty() ? std::string("incomplete header") : why));
    if (storage == EXR_STORAGE_DEEP_SCANLINE || storage == EXR_STORAGE_DEEP_TILED)
        throw Error(path, "a deep EXR (a list of samples per pixel) is not an image wedge reads");
    // In 64 bits: a window from INT_MIN to INT_MAX is 2^32 pixels wide.
    const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0) throw Error(path, "the EXR's data window is empty");
    if (const std::string big = oversize("EXR", uint64_t(w), uint64_t(h)); !big.empty()) throw Error(path, big);
    uint64_t pixelBytes = 0;  // a pixel of every channel, as the file stores it
    for (int c = 0; c < channels->num_channels; ++c) pixelBytes += exrTypeBytes(channels->entries[c].pixel_type);
    // Every channel is read as w x h floats, allocated before any pixel is read.
    const uint64_t count = uint64_t(channels->num_channels), floats = count * uint64_t(w) * uint64_t(h) * sizeof(float);
    checkMemory(path, "the EXR's " + std::to_string(count) + " channels of " + std::to_string(w) + "x" + std::to_string(h) +
                          " floats",
                floats);
    // OpenEXR's buffers: one chunk (a block of lines, or a tile) a buffer as the file stores it,
    // and up to three times that in its decompressor (B44's scratch is twice the chunk); a tiled
    // file read as lines also goes through a row of tiles in floats.
    // The library makes two buffers a thread (one without threads): no more threads than it has
    // chunks to fill two buffers each, so a small image does not get the buffers of a large one.
    int32_t chunks = 1;
    if (exr_get_chunk_count(ctxt, 0, &chunks) != EXR_ERR_SUCCESS || chunks < 1) chunks = 1;
    threads = std::min(threads, chunks / 2);
    const uint64_t buffers = uint64_t(std::max(1, 2 * threads));
    uint64_t chunkBytes = 0, tileRow = 0;
    std::string chunk;
    if (storage == EXR_STORAGE_TILED) {
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t level{};
        exr_tile_round_mode_t round{};
        if (exr_get_tile_descriptor(ctxt, 0, &tw, &th, &level, &round) != EXR_ERR_SUCCESS)
            throw Error(path, "not a readable EXR file: " + (why.empty() ? std::string("no tile description") : why));
        chunkBytes = uint64_t(tw) * th * pixelBytes;
        tileRow = uint64_t(w) * th * count * sizeof(float);
        chunk = std::to_string(tw) + "x" + std::to_string(th) + " tiles";
    } else {
        int32_t lines = 1;
        if (exr_get_scanlines_per_chunk(ctxt, 0, &lines) != EXR_ERR_SUCCESS || lines < 1) lines = 1;
        chunkBytes = uint64_t(lines) * uint64_t(w) * pixelBytes;
        chunk = "blocks of " + std::to_string(lines) + " lines";
    }
    checkMemory(path, "the EXR's floats and OpenEXR's decoding buffers (" + std::to_string(buffers) + " for its " + chunk +
                          (tileRow ? ", and a row of them" : "") + ", " + std::to_string(w) + " pixels wide, " +
                          std::to_string(pixelBytes) + " bytes a pixel)",
                buffers * 4 * chunkBytes + tileRow + floats);
    return threads;
}

}  // namespace

ExrImage readExr(const std::string& path) {
    if (const std::string why = notARegularFile(path); !why.empty()) throw Error(path, why);
    // OpenEXR allocates from the header as it opens a file (an offset per line block: 1 GB for a
    // window 2^31 lines high) unless told the largest image and tile to accept; the library's own
    // guard against damaged files, set to what wedge renders at most.
    static std::once_flag limits;
    std::call_once(limits, [] {
        Imf::Header::setMaxImageSize(kMaxImageSide, kMaxImageSide);
        Imf::Header::setMaxTileSize(kMaxImageSide, kMaxImageSide);
    });
    const int threads = checkExrHeader(path, exrThreads());
    try {
        Imf::InputFile file(path.c_str(), threads);
        const Imath::Box2i dw = file.header().dataWindow();
        // The header as the C++ library read it, checked again: the same bytes, but not the same parser.
        const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0) throw Error(path, "the EXR's data window is empty");
        if (const std::string why = oversize("EXR", uint64_t(w), uint64_t(h)); !why.empty()) throw Error(path, why);
        const Imf::ChannelList& list = file.header().channels();
        uint64_t count = 0;
        for (auto it = list.begin(); it != list.end(); ++it) ++count;
        checkMemory(path, "the EXR's " + std::to_string(count) + " channels of " + std::to_string(w) + "x" +
                              std::to_string(h) + " floats",
                    count * uint64_t(w) * uint64_t(h) * sizeof(float));
        ExrImage img;
        img.width = int(w);
        img.height = int(h);
        Imf::FrameBuffer fb;
        for (auto it = list.begin(); it != list.end(); ++it) {
            auto& v = img.channels[it.name()];
            v.resize(size_t(w) * size_t(h));  // unwritten until OpenEXR reads the lines
            // Slice::Make places the window's origin without pointer arithmetic outside the buffer.
            fb.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, v.data(), dw, sizeof(float), sizeof(float) * size_t(w)));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        return img;
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path, std::string("not a readable EXR file: ") + e.what());
    }
}

// --- PNG -------------------------------------------------------------------------------------

namespace {

/// libpng prints its errors to stderr by default ("libpng error: Read Error" before wedge's own
/// message); this handler keeps the text (and errno, for a write) for wedge's message instead.
struct PngFailure {
    std::string message;
    int error = 0;
};
void onPngError(png_structp p, png_const_charp message) {
    auto* f = static_cast<PngFailure*>(png_get_error_ptr(p));
    f->error = errno;
    f->message = message;
    png_longjmp(p, 1);
}
void onPngWarning(png_structp, png_const_charp) {}

void writePngRgb8(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb) {
    atomicWrite(path, [&](const std::string& tmp) {
        FILE* fp = std::fopen(tmp.c_str(), "wb");
        if (!fp) throw Error(path, std::string("cannot open for writing: ") + std::strerror(errno));
        PngFailure failure;
        png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &failure, onPngError, onPngWarning);
        png_infop info = png_create_info_struct(png);
        if (setjmp(png_jmpbuf(png))) {
            png_destroy_write_struct(&png, &info);
            std::fclose(fp);
            throw Error(path, "cannot write PNG (" + failure.message +
                                  (failure.error ? std::string(": ") + std::strerror(failure.error) : "") + ")");
        }
        png_init_io(png, fp);
        png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                     PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_set_compression_level(png, 6);
        png_write_info(png, info);
        for (int y = 0; y < height; ++y) png_write_row(png, (png_const_bytep)&rgb[size_t(y) * width * 3]);
        png_write_end(png, nullptr);
        png_destroy_write_struct(&png, &info);
        if (std::fclose(fp) != 0) throw Error(path, std::string("cannot finish writing: ") + std::strerror(errno));
    });
}

/// [0, 1] -> 0..255; NaN maps to 0 and the infinities to the nearer end. (Converting them to
/// int first, as the clamp after the conversion once did, is undefined behaviour: UBSan's
/// float-cast-overflow on a render's NaN pixels.) Finite values map as they always did.
unsigned char toByte(float encoded) {
    if (!(encoded > 0.f)) return 0;  // NaN too
    if (encoded >= 1.f) return 255;
    return (unsigned char)(encoded * 255.f + 0.5f);
}

}  // namespace

void writePng(const std::string& path, const Image3f& linear) {
    std::vector<unsigned char> rgb(linear.size() * 3);
    for (size_t i = 0; i < linear.size(); ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = toByte(srgbEncode(linear[i][c]));
    writePngRgb8(path, linear.width(), linear.height(), rgb);
}

void writePngHeat(const std::string& path, const Image1f& values, float lo, float hi) {
    // A perceptually ordered ramp (dark blue -> teal -> yellow), close to viridis at 5 stops.
    static const Vec3f stops[5] = {{0.267f, 0.005f, 0.329f}, {0.231f, 0.322f, 0.545f}, {0.129f, 0.569f, 0.549f},
                                   {0.369f, 0.788f, 0.384f}, {0.993f, 0.906f, 0.144f}};
    std::vector<unsigned char> rgb(values.size() * 3);
    for (size_t i = 0; i < values.size(); ++i) {
        float v = values[i];
        Vec3f c(1.f, 0.f, 1.f);  // magenta marks NaN
        if (std::isfinite(v)) {
            float t = hi > lo ? std::clamp((v - lo) / (hi - lo), 0.f, 1.f) : 0.f;
            float f = t * 4.f;
            int k = std::min(3, int(f));
            float a = f - k;
            c = stops[k] * (1 - a) + stops[k + 1] * a;
        }
        for (int ch = 0; ch < 3; ++ch) rgb[3 * i + ch] = toByte(c[ch]);
    }
    writePngRgb8(path, values.width(), values.height(), rgb);
}

Image3f readPng(const std::string& path) {
    FILE* fp = std::fopen(path.c_str(), "rb");
    if (!fp) throw Error(path, std::string("cannot open: ") + std::strerror(errno));
    unsigned char sig[8];
    if (std::fread(sig, 1, 8, fp) != 8 || png_sig_cmp(sig, 0, 8)) {
        std::fclose(fp);
        throw Error(path, "not a PNG file");
    }
    PngFailure failure;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &failure, onPngError, onPngWarning);
    png_infop info = png_create_info_struct(png);
    std::vector<unsigned char> pixels;
    std::vector<png_bytep> rows;
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(fp);
        throw Error(path, "corrupt PNG file" + (failure.message.empty() ? "" : " (" + failure.message + ")"));
    }
    png_init_io(png, fp);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    // The header's size is not checked against anything before the pixels are allocated: a
    // damaged or hostile header could ask for terabytes (libpng allows 1,000,000 per side).
    // (The message lives in the if's scope only: libpng's later errors longjmp past this point.)
    if (const std::string why = oversize("PNG", png_get_image_width(png, info), png_get_image_height(png, info));
        !why.empty()) {
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(fp);
        throw Error(path, why);
    }
    if (const std::string why = overMemory("PNG", png_get_image_width(png, info), png_get_image_height(png, info), 3);
        !why.empty()) {
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(fp);
        throw Error(path, why);
    }
    png_set_strip_16(png);
    png_set_palette_to_rgb(png);
    png_set_gray_to_rgb(png);
    png_set_strip_alpha(png);
    png_set_expand_gray_1_2_4_to_8(png);
    png_read_update_info(png, info);
    int w = int(png_get_image_width(png, info)), h = int(png_get_image_height(png, info));
    size_t rowBytes = png_get_rowbytes(png, info);
    pixels.resize(rowBytes * h);
    rows.resize(h);
    for (int y = 0; y < h; ++y) rows[y] = &pixels[rowBytes * y];
    png_read_image(png, rows.data());
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    Image3f img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) img(x, y)[c] = srgbDecode(pixels[rowBytes * y + 3 * x + c] / 255.f);
    return img;
}

// --- JPEG (read only: texture maps) ----------------------------------------------------------

Image3f readJpeg(const std::string& path) {
    FILE* fp = std::fopen(path.c_str(), "rb");
    if (!fp) throw Error(path, std::string("cannot open: ") + std::strerror(errno));
    // libjpeg's default error handler prints and exits; this one keeps the message and jumps back.
    struct Failure {
        jpeg_error_mgr base;
        std::jmp_buf jump;
        std::string message;
    } failure;
    jpeg_decompress_struct jpeg;
    jpeg.err = jpeg_std_error(&failure.base);
    failure.base.error_exit = [](j_common_ptr c) {
        Failure* f = reinterpret_cast<Failure*>(c->err);
        char text[JMSG_LENGTH_MAX];
        (*c->err->format_message)(c, text);
        f->message = text;
        std::longjmp(f->jump, 1);
    };
    // Warnings (a truncated file's, damaged data's) are counted, not printed: they fail the read below.
    failure.base.emit_message = [](j_common_ptr c, int level) {
        if (level < 0) ++c->err->num_warnings;
    };
    std::vector<unsigned char> pixels;
    if (setjmp(failure.jump)) {
        jpeg_destroy_decompress(&jpeg);
        std::fclose(fp);
        throw Error(path, "corrupt JPEG file (" + failure.message + ")");
    }
    jpeg_create_decompress(&jpeg);
    jpeg_stdio_src(&jpeg, fp);
    jpeg_read_header(&jpeg, TRUE);
    if (const std::string why = oversize("JPEG", jpeg.image_width, jpeg.image_height); !why.empty()) {
        jpeg_destroy_decompress(&jpeg);
        std::fclose(fp);
        throw Error(path, why);
    }
    if (const std::string why = overMemory("JPEG", jpeg.image_width, jpeg.image_height, 3); !why.empty()) {
        jpeg_destroy_decompress(&jpeg);
        std::fclose(fp);
        throw Error(path, why);
    }
    if (jpeg.jpeg_color_space == JCS_CMYK || jpeg.jpeg_color_space == JCS_YCCK) {
        jpeg_destroy_decompress(&jpeg);
        std::fclose(fp);
        throw Error(path, "a CMYK JPEG (wedge reads RGB and greyscale JPEGs)");
    }
    jpeg.out_color_space = JCS_RGB;  // greyscale and YCbCr alike
    jpeg_start_decompress(&jpeg);
    const int w = int(jpeg.output_width), h = int(jpeg.output_height);
    pixels.resize(size_t(w) * h * 3);
    while (jpeg.output_scanline < jpeg.output_height) {
        JSAMPROW row = &pixels[size_t(jpeg.output_scanline) * w * 3];
        jpeg_read_scanlines(&jpeg, &row, 1);
    }
    const bool truncated = jpeg.err->num_warnings > 0;
    jpeg_finish_decompress(&jpeg);
    jpeg_destroy_decompress(&jpeg);
    std::fclose(fp);
    // libjpeg fills a file that ends early with grey and warns ("Premature end of JPEG file").
    if (truncated) throw Error(path, "corrupt JPEG file (it ends early or has damaged data)");
    Image3f img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) img(x, y)[c] = srgbDecode(pixels[(size_t(y) * w + x) * 3 + c] / 255.f);
    return img;
}

// --- PFM -------------------------------------------------------------------------------------

void writePfm(const std::string& path, const Image3f& img) {
    atomicWrite(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) throw Error(path, "cannot open for writing");
        out << "PF\n" << img.width() << " " << img.height() << "\n-1.0\n";  // negative scale: little-endian
        for (int y = img.height() - 1; y >= 0; --y)  // PFM stores rows bottom to top
            for (int x = 0; x < img.width(); ++x) {
                float rgb[3] = {img(x, y).x, img(x, y).y, img(x, y).z};
                out.write(reinterpret_cast<const char*>(rgb), sizeof(rgb));
            }
        out.close();  // the last buffer reaches the disk here
        if (!out) throw Error(path, std::string("cannot write PFM: ") + std::strerror(errno));
    });
}

Image3f readPfm(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "cannot open");
    std::string magic;
    int w = 0, h = 0;
    float scale = 0;
    in >> magic >> w >> h >> scale;
    in.get();
    if (!in || (magic != "PF" && magic != "Pf") || w <= 0 || h <= 0 || scale == 0)
        throw Error(path, "not a PFM file (bad header)");
    if (scale > 0) throw Error(path, "big-endian PFM is not supported");
    int channels = magic == "PF" ? 3 : 1;
    // The header's size against the bytes that follow it, before allocating: a damaged header
    // ("99999 99999") would otherwise ask for 120 GB.
    const auto dataStart = in.tellg();
    in.seekg(0, std::ios::end);
    const uint64_t available = uint64_t(in.tellg() - dataStart);
    in.seekg(dataStart);
    if (uint64_t(w) * uint64_t(h) * channels * sizeof(float) > available)
        throw Error(path, "truncated PFM data (the header gives " + std::to_string(w) + "x" + std::to_string(h) + ")");
    if (const std::string why = overMemory("PFM", uint64_t(w), uint64_t(h), channels * sizeof(float)); !why.empty()) throw Error(path, why);
    std::vector<float> raw(size_t(w) * h * channels);
    in.read(reinterpret_cast<char*>(raw.data()), raw.size() * sizeof(float));
    if (!in) throw Error(path, "truncated PFM data");
    Image3f img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float* p = &raw[(size_t(h - 1 - y) * w + x) * channels];
            img(x, y) = channels == 3 ? Vec3f(p[0], p[1], p[2]) : Vec3f(p[0]);
        }
    return img;
}

// --- by extension ----------------------------------------------------------------------------

Image3f readColor(const std::string& path) {
    if (const std::string why = notARegularFile(path); !why.empty()) throw Error(path, why);
    std::string e = extension(path);
    if (e == ".png") return readPng(path);
    if (e == ".pfm") return readPfm(path);
    if (e == ".exr") {
        ExrImage exr = readExr(path);
        for (const char* c : {"R", "G", "B"})
            if (!exr.channels.count(c)) throw Error(path, std::string("EXR has no channel ") + c);
        Image3f img(exr.width, exr.height);
        for (size_t i = 0; i < img.size(); ++i)
            img[i] = {exr.channels["R"][i], exr.channels["G"][i], exr.channels["B"][i]};
        return img;
    }
    throw Error(path, "unsupported image format '" + e + "' (expected .exr, .png or .pfm)");
}

void writeColor(const std::string& path, const Image3f& linear) {
    std::string e = extension(path);
    if (e == ".png") return writePng(path, linear);
    if (e == ".pfm") return writePfm(path, linear);
    if (e == ".exr") {
        const float* base = &linear[0].x;
        return writeExr(path, linear.width(), linear.height(), {{"R", base, 3}, {"G", base + 1, 3}, {"B", base + 2, 3}});
    }
    throw Error(path, "unsupported image format '" + e + "' (expected .exr, .png or .pfm)");
}

}  // namespace wedge::io

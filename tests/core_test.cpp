// Core and I/O: the per-pixel sample generator's stratification and determinism, and image
// files written and read back (EXR with named channels, PFM orientation, PNG sRGB, JPEG texture maps).
#include <gtest/gtest.h>

#include <algorithm>
#include <zlib.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <set>
#include <vector>

#include "core/cancel.h"
#include "core/error.h"
#include "core/image.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/memory_limit.h"
#include "core/sampler.h"
#include "io/image_io.h"
#include "io/text_file.h"
#include "render/output.h"
#include "test_util.h"

using namespace wedge;

TEST(Sampler, EveryPowerOfTwoPrefixIsStratified) {
    // (0,2)-sequence in base 2: the first 2^k points of a pair fall one in each elementary
    // interval of area 2^-k (checked for 4x4, 16x1 and 1x16 with 16 points, 8x8 with 64).
    for (uint32_t pixel = 0; pixel < 40; ++pixel) {
        PixelSampler s(17, pixel);
        for (uint32_t pair = 0; pair < 6; ++pair) {
            int a[16] = {}, b[16] = {}, c[16] = {}, d[64] = {};
            for (uint32_t i = 0; i < 64; ++i) {
                Vec2f v = s.get2D(i, pair);
                ASSERT_GE(v.x, 0.f);
                ASSERT_LT(v.x, 1.f);
                if (i < 16) {
                    ++a[int(v.x * 4) * 4 + int(v.y * 4)];
                    ++b[int(v.x * 16)];
                    ++c[int(v.y * 16)];
                }
                ++d[int(v.x * 8) * 8 + int(v.y * 8)];
            }
            for (int k = 0; k < 16; ++k) ASSERT_TRUE(a[k] == 1 && b[k] == 1 && c[k] == 1) << pixel << " " << pair;
            for (int k = 0; k < 64; ++k) ASSERT_EQ(d[k], 1);
        }
    }
}

TEST(Sampler, CameraPointsAreStratifiedInFourDimensionsJointly) {
    // Unscrambled Sobol dimensions 0-3: point i is the XOR of the direction numbers v_k of i's set
    // bits, v_k = m_k / 2^k. By hand from Joe and Kuo's m (dimension 2: 1, 3, then
    // m_3 = m_1 ^ 4 m_1 ^ 2 m_2 = 3; dimension 3: 1, 3, 1): point 2 = v_2, point 3 = v_1 ^ v_2,
    // point 6 = v_2 ^ v_3. Points 1-4 in Gray-code order are 1, 3, 2, 6 in index order, and these
    // are the sequence's published first points (0.5, ...), (0.75, 0.25, ...), (0.25, 0.75, ...),
    // (0.375, 0.375, 0.625, ...).
    auto sobol = [](uint32_t i, int d) { return d == 0 ? reverseBits32(i) : reverseBits32(sobolReversed(i, d)); };
    auto at = [&](uint32_t i, int d) { return double(sobol(i, d)) * 0x1p-32; };
    const double p2[4] = {0.25, 0.75, 0.75, 0.75}, p3[4] = {0.75, 0.25, 0.25, 0.25}, p6[4] = {0.375, 0.375, 0.625, 0.875};
    for (int d = 0; d < 4; ++d) {
        EXPECT_EQ(at(1, d), 0.5);
        EXPECT_EQ(at(2, d), p2[d]);
        EXPECT_EQ(at(3, d), p3[d]);
        EXPECT_EQ(at(6, d), p6[d]);
    }
    EXPECT_EQ(sobolReversed(12345, 1), sobol1Reversed(12345));

    for (uint32_t pixel = 0; pixel < 40; ++pixel) {
        PixelSampler s(23, pixel);
        Vec2f a[16], b[16];
        for (uint32_t first = 0; first < 256; first += 16) {
            s.get4DBatch(first, 16, 0, a, b);
            for (uint32_t k = 0; k < 16; ++k) {
                // Dimensions 0-1 are the pair's 2D points; every coordinate lies in [0, 1).
                Vec2f p = s.get2D(first + k, 0), q, r;
                ASSERT_EQ(a[k].x, p.x);
                ASSERT_EQ(a[k].y, p.y);
                s.get4D(first + k, 0, q, r);
                ASSERT_EQ(b[k].x, r.x);
                ASSERT_EQ(b[k].y, r.y);
                for (float v : {b[k].x, b[k].y}) ASSERT_TRUE(v >= 0.f && v < 1.f);
            }
            // Every 16 consecutive points from a multiple of 16 (a power-of-two block of the
            // sequence) put one point in each of the 16 boxes that halve each of the 4 axes.
            int box[16] = {};
            for (uint32_t k = 0; k < 16; ++k)
                ++box[(a[k].x >= 0.5f) * 8 + (a[k].y >= 0.5f) * 4 + (b[k].x >= 0.5f) * 2 + (b[k].y >= 0.5f)];
            for (int k = 0; k < 16; ++k) ASSERT_EQ(box[k], 1) << pixel << " " << first;
            // The lens pair (dimensions 2-3) is a (1,2)-sequence: 16 points, at most 2 in each
            // elementary interval of area 1/16, and one in each of the 4x4 squares.
            for (int j = 0; j <= 4; ++j) {
                int c[16] = {}, sq[16] = {};
                for (uint32_t k = 0; k < 16; ++k) {
                    ++c[int(b[k].x * float(1 << j)) * (1 << (4 - j)) + int(b[k].y * float(1 << (4 - j)))];
                    if (j == 0) ++sq[int(b[k].x * 4) * 4 + int(b[k].y * 4)];
                }
                for (int k = 0; k < 16; ++k) ASSERT_LE(c[k], 2);
                if (j == 0) {
                    for (int k = 0; k < 16; ++k) ASSERT_EQ(sq[k], 1);
                }
            }
        }
    }
}

TEST(Sampler, DependsOnlyOnSeedPixelIndexAndPair) {
    PixelSampler a(5, 123), b(5, 123), c(6, 123), d(5, 124);
    EXPECT_EQ(a.get2D(7, 2).x, b.get2D(7, 2).x);
    EXPECT_NE(a.get2D(7, 2).x, c.get2D(7, 2).x);
    EXPECT_NE(a.get2D(7, 2).x, d.get2D(7, 2).x);
    EXPECT_NE(a.get2D(7, 2).x, a.get2D(7, 3).x);
    EXPECT_EQ(reverseBits32(sobol1Reversed(12345)), sobol1(12345));
}

TEST(Sampler, IndependentPointsAreUniformAndNotStratified) {
    // --sampler independent: uniform in [0, 1)^2 (moments over 4096 points: the means' standard
    // error is 0.0045), the batches and get4D's first half the same points as get2D, and a
    // pixel's 16 points only by chance one in each of 16 strata (Sobol's always are: above;
    // independent ones with probability 16! / 16^16, about 1e-6).
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int stratified = 0;
    for (uint32_t pixel = 0; pixel < 256; ++pixel) {
        PixelSampler s(17, pixel, true);
        ASSERT_TRUE(s.independent());
        Vec2f batch[16], a[16], b[16];
        s.get2DBatch(0, 16, 2, batch);
        s.get4DBatch(0, 16, 0, a, b);
        int strata[16] = {};
        for (uint32_t i = 0; i < 16; ++i) {
            const Vec2f v = s.get2D(i, 2);
            ASSERT_EQ(v.x, batch[i].x);
            ASSERT_EQ(v.y, batch[i].y);
            ASSERT_EQ(s.get2D(i, 0).x, a[i].x);
            ASSERT_NE(a[i].x, b[i].x);
            ASSERT_GE(v.x, 0.f);
            ASSERT_LT(v.x, 1.f);
            ASSERT_GE(v.y, 0.f);
            ASSERT_LT(v.y, 1.f);
            sx += v.x, sy += v.y, sxx += double(v.x) * v.x, sxy += double(v.x) * v.y;
            ++strata[int(v.x * 16)];
        }
        stratified += std::all_of(strata, strata + 16, [](int c) { return c == 1; }) ? 1 : 0;
        // Not the Sobol points of the same seed and pixel.
        EXPECT_NE(s.get2D(3, 2).x, PixelSampler(17, pixel).get2D(3, 2).x);
    }
    const double n = 4096;
    EXPECT_NEAR(sx / n, 0.5, 0.02);
    EXPECT_NEAR(sy / n, 0.5, 0.02);
    EXPECT_NEAR(sxx / n - sqr(sx / n), 1.0 / 12, 0.01);
    EXPECT_NEAR(sxy / n - (sx / n) * (sy / n), 0.0, 0.01);  // the two dimensions uncorrelated
    EXPECT_EQ(stratified, 0);
}

// A cancellation request stops the parallel loops and the progress counters, which every stage of
// a render goes through, with Cancelled; cleared, they run to the end again.
TEST(Cancel, StopsLoopsAndProgressUntilCleared) {
    ThreadLimit limit(2);
    std::atomic<int> rows{0};
    auto count = [&](int) { ++rows; };
    requestCancel();
    EXPECT_THROW(parallelRows(64, count), Cancelled);
    EXPECT_THROW(parallelTiles(64, 64, 16, [&](int, int, int, int) { ++rows; }), Cancelled);
    EXPECT_EQ(rows, 0) << "no block starts once cancellation was requested";
    Progress progress("test", 10, false);
    EXPECT_THROW(progress.add(1), Cancelled);
    // Requested midway, the loop stops after the blocks already running.
    clearCancel();
    rows = 0;
    EXPECT_THROW(parallelRows(4096, [&](int y) {
                     if (y == 0) requestCancel();
                     ++rows;
                 }),
                 Cancelled);
    EXPECT_LT(rows, 4096);
    clearCancel();
    rows = 0;
    parallelRows(64, count);
    EXPECT_EQ(rows, 64);
    progress.add(1);
}

TEST(Image, FillsAndCopiesEveryPixelOverReusedMemory) {
    // Image leaves implicit-lifetime pixels unwritten until its parallel fill (UnwrittenAllocator):
    // every pixel must still hold the fill value, also where the allocator hands back memory a
    // freed image had written, and for types whose default member initialisers are the only
    // initialisation they get (Vec3f, a struct with an infinity in it).
    struct Px {
        float a = 1.f, b = kInf;
        uint32_t n = 7;
    };
    for (int round = 0; round < 3; ++round) {
        {
            Image3f dirty(1500, 1100, Vec3f(-5.f));  // over 2 MiB: the large-block path
            Image<Px> dirtyPx(700, 900, Px{-1.f, -1.f, 99});
        }
        Image3f zero(1500, 1100);
        Image<Px> px(700, 900);
        Image1f seven(33, 17, 7.f);  // below 2 MiB: malloc's path
        for (size_t i = 0; i < zero.size(); ++i) ASSERT_EQ(zero[i].x + zero[i].y + zero[i].z, 0.f) << i;
        for (size_t i = 0; i < px.size(); ++i) {
            ASSERT_EQ(px[i].a, 1.f) << i;
            ASSERT_EQ(px[i].b, kInf) << i;
            ASSERT_EQ(px[i].n, 7u) << i;
        }
        for (size_t i = 0; i < seven.size(); ++i) ASSERT_EQ(seven[i], 7.f);
        // Copies (parallel) equal their source, and assignment replaces the size too.
        px[12345].n = 3;
        Image<Px> copy(px);
        ASSERT_EQ(copy.width(), 700);
        ASSERT_EQ(copy.height(), 900);
        for (size_t i = 0; i < px.size(); ++i) ASSERT_EQ(copy[i].n, px[i].n) << i;
        Image<Px> assigned(3, 3);
        assigned = copy;
        EXPECT_EQ(assigned.width(), 700);
        EXPECT_EQ(assigned[12345].n, 3u);
        const Image<Px>& self = assigned;  // through a reference: clang warns on `x = x`
        assigned = self;                    // self-assignment keeps the pixels
        EXPECT_EQ(assigned[12345].n, 3u);
    }
}

TEST(ImageIo, RoundTrips) {
    std::string dir = test::tempDir();
    Image3f img(5, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x) img(x, y) = Vec3f(0.1f * x, 0.2f * y, 0.05f * (x + y));
    io::writeColor(dir + "/a.exr", img);
    io::writeColor(dir + "/a.pfm", img);
    io::writeColor(dir + "/a.png", img);
    Image3f e = io::readColor(dir + "/a.exr"), p = io::readColor(dir + "/a.pfm"), q = io::readColor(dir + "/a.png");
    for (size_t i = 0; i < img.size(); ++i) {
        EXPECT_EQ(e[i], img[i]);
        EXPECT_EQ(p[i], img[i]);  // PFM rows are bottom to top on disk; the reader flips them back
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(q[i][c], img[i][c], 0.01f);  // 8-bit sRGB
    }
    // Named channels.
    float plane[15];
    for (int i = 0; i < 15; ++i) plane[i] = float(i);
    io::writeExr(dir + "/b.exr", 5, 3, {{"depth", plane, 1}});
    io::ExrImage b = io::readExr(dir + "/b.exr");
    ASSERT_TRUE(b.channels.count("depth"));
    EXPECT_EQ(b.channels["depth"][7], 7.f);
}

TEST(ImageIo, BadFilesAreErrors) {
    std::string dir = test::tempDir();
    test::writeFile(dir + "/x.png", "not a png");
    test::writeFile(dir + "/x.pfm", "PF\n-3 2\n-1\n");
    test::writeFile(dir + "/x.exr", "garbage");
    for (const char* f : {"/x.png", "/x.pfm", "/x.exr", "/missing.png"}) EXPECT_THROW(io::readColor(dir + f), Error) << f;
    EXPECT_THROW(io::readColor(dir + "/x.bmp"), Error);
    EXPECT_THROW(io::checkOutputPath(dir + "/y.jpg", {".png"}), Error);
    EXPECT_FALSE(std::filesystem::exists(dir + "/y.jpg"));
}

/// The message of the Error that reading `path` throws ("" if none).
std::string readError(const std::string& path) {
    return test::errorOf([&] { io::readColor(path); });
}

TEST(ImageIo, HeadersAreCheckedBeforeAllocating) {
    // A damaged header must not make a reader allocate what it asks for: "99999 99999" in a PFM
    // was 120 GB and ended in "out of memory" (exit code 1), not an error naming the file.
    std::string dir = test::tempDir();
    Image3f img(4, 2, Vec3f(0.5f));
    io::writeColor(dir + "/a.pfm", img);
    std::string pfm = test::readFile(dir + "/a.pfm");
    test::writeFile(dir + "/huge.pfm", "PF\n99999 99999\n-1.0\n" + pfm.substr(pfm.size() - 4 * 2 * 3 * 4));
    EXPECT_NE(readError(dir + "/huge.pfm").find("truncated PFM data (the header gives 99999x99999)"), std::string::npos)
        << readError(dir + "/huge.pfm");
    test::writeFile(dir + "/short.pfm", pfm.substr(0, pfm.size() - 4));
    EXPECT_NE(readError(dir + "/short.pfm").find("truncated PFM data"), std::string::npos);
    EXPECT_EQ(readError(dir + "/a.pfm"), "");

    // A PNG whose IHDR (with a valid CRC) claims 900000 x 900000 pixels.
    io::writeColor(dir + "/a.png", img);
    std::string png = test::readFile(dir + "/a.png");
    const size_t ihdr = png.find("IHDR");
    ASSERT_NE(ihdr, std::string::npos);
    auto put32 = [&](size_t at, uint32_t v) {
        for (int k = 0; k < 4; ++k) png[at + k] = char(v >> (24 - 8 * k));
    };
    put32(ihdr + 4, 900000);
    put32(ihdr + 8, 900000);
    put32(ihdr + 17, uint32_t(crc32(0, reinterpret_cast<const Bytef*>(png.data() + ihdr), 17)));
    test::writeFile(dir + "/huge.png", png);
    EXPECT_NE(readError(dir + "/huge.png").find("the PNG's header gives 900000x900000 pixels"), std::string::npos)
        << readError(dir + "/huge.png");
    // A PNG cut short: libpng's reason is in wedge's message (not printed by libpng itself).
    test::writeFile(dir + "/cut.png", test::readFile(dir + "/a.png").substr(0, 60));
    EXPECT_NE(readError(dir + "/cut.png").find("corrupt PNG file ("), std::string::npos) << readError(dir + "/cut.png");
}

TEST(ImageIo, ExrHeadersAreCheckedBeforeAllocating) {
    // readExr sized every channel from the header before reading a pixel: a 400 KB file whose
    // header gives 50000 x 50000 grew `wedge compare` to 24 GB until the kernel killed it.
    std::string dir = test::tempDir();
    test::writeFile(dir + "/bomb.exr", test::exrHeader(0, 0, 49999, 49999, 3, 50000));
    const std::string bomb = readError(dir + "/bomb.exr");
    EXPECT_NE(bomb.find(dir + "/bomb.exr: "), std::string::npos) << bomb;
    EXPECT_NE(bomb.find("16384"), std::string::npos) << "names the bound: " << bomb;
    // A window over all of int's range is 2^32 pixels wide: its size must not overflow int.
    test::writeFile(dir + "/wide.exr", test::exrHeader(INT_MIN, 0, INT_MAX, 0, 1, 1));
    EXPECT_NE(readError(dir + "/wide.exr").find("not a readable EXR file"), std::string::npos) << readError(dir + "/wide.exr");
    test::writeFile(dir + "/all.exr", test::exrHeader(INT_MIN, INT_MIN, INT_MAX, INT_MAX, 1, 0));
    EXPECT_NE(readError(dir + "/all.exr").find(dir + "/all.exr: "), std::string::npos) << readError(dir + "/all.exr");
    // Within the side bound, the channels' floats against the memory limit: 3 x 4096 x 4096 x 4 bytes.
    test::writeFile(dir + "/deep.exr", test::exrHeader(0, 0, 4095, 4095, 3, 4096));
    setMemoryLimit(uint64_t(64) << 20);
    const std::string deep = readError(dir + "/deep.exr");
    setMemoryLimit(0);
    EXPECT_NE(deep.find("the EXR's 3 channels of 4096x4096 floats needs 192.0 MiB, more than the memory limit of 64.0 MiB (--max-memory)"),
              std::string::npos)
        << deep;
    // The same file within the limit is read, and refused for what it is: lines that are not there.
    const std::string missing = readError(dir + "/deep.exr");
    EXPECT_NE(missing.find("not a readable EXR file"), std::string::npos) << missing;
}

TEST(ImageIo, ExrAttributesAndDecodingBuffersAreCheckedBeforeOpenEXRAllocatesThem) {
    std::string dir = test::tempDir();
    // An attribute of a type OpenEXR does not know, declaring 2 GB in a 400-byte file: the C++
    // library allocated the declared size before reading it (fuzz_exr spent its time there).
    std::string opaque = "blob";
    opaque += '\0';
    opaque += "mystery";
    opaque += '\0';
    opaque += std::string("\xff\xff\xff\x7f", 4);  // 2^31 - 1 bytes
    opaque += "abcd";
    test::writeFile(dir + "/opaque.exr", test::exrHeader(0, 0, 7, 7, 1, 8, 0, opaque));
    const std::string big = readError(dir + "/opaque.exr");
    EXPECT_NE(big.find(dir + "/opaque.exr: not a readable EXR file: "), std::string::npos) << big;
    EXPECT_NE(big.find("blob"), std::string::npos) << "names the attribute: " << big;
    // A header whose floats fit (16384 x 1 x 99 channels: 6.2 MiB) but whose compression (DWAB:
    // blocks of 256 lines) has OpenEXR size each decoding buffer for 256 lines of it.
    test::writeFile(dir + "/dwab.exr", test::exrHeader(0, 0, 16383, 0, 99, 1, 9));
    setMemoryLimit(uint64_t(1) << 30);
    const std::string wide = readError(dir + "/dwab.exr");
    setMemoryLimit(0);
    // One chunk: one buffer, whatever the threads (6.2 GiB with the decompressor's scratch).
    EXPECT_NE(wide.find(dir + "/dwab.exr: the EXR's floats and OpenEXR's decoding buffers (1 for its blocks of 256 "
                              "lines, 16384 pixels wide, 396 bytes a pixel) needs 6.2 GiB"),
              std::string::npos)
        << wide;
    EXPECT_NE(wide.find("more than the memory limit of 1.0 GiB (--max-memory)"), std::string::npos) << wide;
    // A deep file is refused for what it is (version flag 0x800: non-image parts).
    std::string deep = test::exrHeader(0, 0, 7, 7, 1, 8);
    deep[5] = 0x08;
    test::writeFile(dir + "/deep-data.exr", deep);
    EXPECT_NE(readError(dir + "/deep-data.exr").find(dir + "/deep-data.exr: "), std::string::npos);
}

TEST(ImageIo, PathsTheFileSystemRefusesAreErrorsNotExceptions) {
    // A name over NAME_MAX made std::filesystem::is_regular_file throw past wedge's errors
    // (fuzz_obj: a 4 KB map_Kd name; the CLI said "internal error" and exited 1).
    const std::string dir = test::tempDir(), longName = dir + "/" + std::string(300, 'x') + ".png";
    EXPECT_EQ(io::notARegularFile(longName), std::string(std::strerror(ENAMETOOLONG)));
    EXPECT_EQ(io::notARegularFile(dir + "/missing.png"), "no such file");
    EXPECT_EQ(io::notARegularFile(dir), "is a directory");
    EXPECT_NE(readError(longName).find(longName + ": File name too long"), std::string::npos) << readError(longName);
    test::writeFile(dir + "/a.txt", "x");
    EXPECT_EQ(io::notARegularFile(dir + "/a.txt"), "");
}

TEST(ImageIo, TheMemoryLimitCoversEveryReader) {
    std::string dir = test::tempDir();
    Image3f img(64, 64, Vec3f(0.25f));
    for (const char* f : {"/a.png", "/a.pfm", "/a.exr"}) io::writeColor(dir + f, img);
    test::writeJpeg(dir + "/a.jpg", 64, 64, 1, std::vector<unsigned char>(64 * 64, 90), 90);
    setMemoryLimit(1000);  // bytes: less than any 64 x 64 image
    std::vector<std::string> errors;
    for (const char* f : {"/a.png", "/a.pfm", "/a.exr"}) errors.push_back(readError(dir + f));
    errors.push_back(test::errorOf([&] { io::readJpeg(dir + "/a.jpg"); }));
    setMemoryLimit(0);
    for (const std::string& e : errors) EXPECT_NE(e.find("more than the memory limit of 1000 bytes (--max-memory)"), std::string::npos) << e;
    EXPECT_EQ(readError(dir + "/a.png"), "");
    EXPECT_GT(memoryLimit(), uint64_t(1) << 20) << "the default: the machine's memory";
    EXPECT_EQ(parseMemorySize("512M", "--max-memory"), uint64_t(512) << 20);
    EXPECT_EQ(parseMemorySize("1.5GiB", "--max-memory"), uint64_t(3) << 29);
    EXPECT_EQ(parseMemorySize("4096", "--max-memory"), 4096u);
    for (const char* bad : {"", "-1G", "nan", "8Q", "1e30T", "0"})
        EXPECT_NE(test::errorOf([&] { parseMemorySize(bad, "--max-memory"); }).find("--max-memory: '"), std::string::npos) << bad;
}

TEST(ImageIo, PngMapsNonFiniteValuesToFixedBytes) {
    // NaN went through int() (undefined behaviour; UBSan stopped on it): now black, +inf white.
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    Image3f img(4, 1);
    img(0, 0) = Vec3f(nan, nan, nan);
    img(1, 0) = Vec3f(inf, inf, inf);
    img(2, 0) = Vec3f(-inf, -inf, -inf);
    img(3, 0) = Vec3f(0.5f, 2.f, -1.f);
    std::string dir = test::tempDir();
    io::writePng(dir + "/n.png", img);
    const Image3f back = io::readPng(dir + "/n.png");
    EXPECT_EQ(back(0, 0), Vec3f(0.f));
    EXPECT_EQ(back(1, 0), Vec3f(1.f));
    EXPECT_EQ(back(2, 0), Vec3f(0.f));
    EXPECT_NEAR(back(3, 0).x, 0.5f, 0.01f);
    EXPECT_EQ(back(3, 0).y, 1.f);
    EXPECT_EQ(back(3, 0).z, 0.f);
}

TEST(RenderStats, NonFinitePixelsCountsSamplesAndColour) {
    render::RenderResult r;
    r.color = Image3f(4, 2, Vec3f(0.5f));
    r.buffers = FrameBuffers(4, 2);
    EXPECT_EQ(render::nonFinitePixels(r), 0u);
    r.color(1, 0).y = std::numeric_limits<float>::quiet_NaN();
    r.buffers.direct(2, 1).x = std::numeric_limits<float>::infinity();
    r.buffers.other[1].indirect(3, 1).z = -std::numeric_limits<float>::infinity();
    r.buffers.rest(1, 0).x = std::numeric_limits<float>::quiet_NaN();  // the same pixel as the colour's
    EXPECT_EQ(render::nonFinitePixels(r), 3u);
    // The planes that are infinite by design (no occluder: an infinite slope) do not count.
    r.buffers.sMax(0, 0) = std::numeric_limits<float>::infinity();
    EXPECT_EQ(render::nonFinitePixels(r), 3u);
    EXPECT_EQ(render::statsJson(r, "s")["nonfinite_pixels"], 3);
}

TEST(ImageIo, JpegTexturesDecodeFromSrgbToLinear) {
    // Four flat 16 x 16 quadrants (whole blocks, so the lossy code keeps them flat) and a
    // greyscale image: each pixel is its sRGB byte decoded to linear, to within JPEG's rounding.
    std::string dir = test::tempDir();
    const unsigned char quadrant[4][3] = {{200, 40, 40}, {40, 200, 40}, {40, 40, 200}, {128, 128, 128}};
    std::vector<unsigned char> rgb(32 * 32 * 3), grey(16 * 8, 90);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            for (int c = 0; c < 3; ++c) rgb[(size_t(y) * 32 + x) * 3 + c] = quadrant[(y / 16) * 2 + x / 16][c];
    test::writeJpeg(dir + "/q.jpg", 32, 32, 3, rgb, 95);
    test::writeJpeg(dir + "/g.jpeg", 16, 8, 1, grey, 95);
    auto linear = [](int byte) { return byte <= 10 ? byte / 255.f / 12.92f : std::pow((byte / 255.f + 0.055f) / 1.055f, 2.4f); };
    const Image3f q = io::readJpeg(dir + "/q.jpg");
    ASSERT_EQ(q.width(), 32);
    ASSERT_EQ(q.height(), 32);
    for (int k = 0; k < 4; ++k) {
        const Vec3f got = q(8 + 16 * (k % 2), 8 + 16 * (k / 2));
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], linear(quadrant[k][c]), 0.03f * linear(quadrant[k][c]) + 0.002f) << "quadrant " << k << " channel " << c;
    }
    const Image3f g = io::readJpeg(dir + "/g.jpeg");
    ASSERT_EQ(g.width(), 16);
    ASSERT_EQ(g.height(), 8);
    EXPECT_NEAR(g(5, 3).x, linear(90), 0.02f * linear(90));
    EXPECT_EQ(g(5, 3).x, g(5, 3).y);
    EXPECT_EQ(g(5, 3).x, g(5, 3).z);

    // Damaged files: errors that name the file, libjpeg's reason kept (not printed by libjpeg).
    auto jpegError = [](const std::string& path) { return test::errorOf([&] { io::readJpeg(path); }); };
    test::writeFile(dir + "/text.jpg", "not a jpeg");
    EXPECT_NE(jpegError(dir + "/text.jpg").find(dir + "/text.jpg: corrupt JPEG file (Not a JPEG file"), std::string::npos)
        << jpegError(dir + "/text.jpg");
    const std::string bytes = test::readFile(dir + "/q.jpg");
    test::writeFile(dir + "/half.jpg", bytes.substr(0, bytes.size() / 2));  // cut in its tables
    EXPECT_NE(jpegError(dir + "/half.jpg").find("corrupt JPEG file (Invalid JPEG file structure"), std::string::npos)
        << jpegError(dir + "/half.jpg");
    // Cut in its pixel data: libjpeg fills the rest with grey and only warns.
    test::writeFile(dir + "/cut.jpg", bytes.substr(0, bytes.size() - 40));
    EXPECT_NE(jpegError(dir + "/cut.jpg").find("corrupt JPEG file (it ends early"), std::string::npos) << jpegError(dir + "/cut.jpg");
    // A frame header (SOF0: FF C0, length, precision, height, width) claiming 60000 x 60000.
    std::string huge = bytes;
    const size_t sof = huge.find("\xFF\xC0");
    ASSERT_NE(sof, std::string::npos);
    for (size_t at : {sof + 5, sof + 7}) {
        huge[at] = char(60000 >> 8);
        huge[at + 1] = char(60000 & 255);
    }
    test::writeFile(dir + "/huge.jpg", huge);
    EXPECT_NE(jpegError(dir + "/huge.jpg").find("the JPEG's header gives 60000x60000 pixels"), std::string::npos)
        << jpegError(dir + "/huge.jpg");
    EXPECT_NE(jpegError(dir + "/missing.jpg").find("cannot open"), std::string::npos);
}

TEST(Parallel, TilesAreTheSameOnAnyNumberOfThreadsAndEveryRun) {
    // A body that batches its tile's work (the sampler's Embree streams) gives the same results
    // only where the tiles are the same. The tiles are split down to the grain (so they are the
    // same whatever the scheduling), and every pixel is in exactly one.
    constexpr int W = 1021, H = 517, kGrain = 16;
    auto tiles = [&](int threads, bool uneven) {
        ThreadLimit limit(threads);
        std::mutex m;
        std::set<std::array<int, 4>> out;
        std::vector<std::atomic<int>> covered(size_t(W) * H);
        parallelTiles(W, H, kGrain, [&](int x0, int x1, int y0, int y1) {
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) ++covered[size_t(y) * W + x];
            volatile double spin = 0;  // uneven work, so that threads steal
            if (uneven)
                for (int k = 0; k < ((x0 * 7 + y0 * 3) % 5) * 2000; ++k) spin = spin + k;
            std::lock_guard<std::mutex> lock(m);
            out.insert({x0, x1, y0, y1});
        });
        for (const auto& c : covered) EXPECT_EQ(c.load(), 1);
        return out;
    };
    const auto one = tiles(1, false);
    for (const auto& [x0, x1, y0, y1] : one) {
        EXPECT_LE(x1 - x0, kGrain);
        EXPECT_LE(y1 - y0, kGrain);
    }
    for (int run = 0; run < 3; ++run) {
        EXPECT_EQ(tiles(2, run % 2 == 0), one);
        EXPECT_EQ(tiles(4, run % 2 == 1), one);
    }
}

// render/distribution.h without MPI: N threads of one process stand for N ranks (an allgather
// over a std::barrier), each rendering with its own Distribution. Every rank's result is one
// process's bit for bit, for every method, with and without the light field: what `mpirun -n N
// wedge render` relies on (tests/mpi_test.cpp runs that), checked here also in builds without
// MPI and under the sanitizers.
#include <gtest/gtest.h>

#include <barrier>
#include <cstring>
#include <thread>

#include "core/timer.h"
#include "render/distribution.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

using namespace wedge;

namespace {

/// What the ranks share: one slot each, and a barrier on either side of reading them.
struct Ring {
    explicit Ring(int n) : slots(static_cast<size_t>(n)), barrier(n) {}
    std::vector<std::vector<char>> slots;
    std::barrier<> barrier;
};

class ThreadRank : public render::Distribution {
public:
    ThreadRank(Ring& ring, int rank) : m_ring(ring), m_rank(rank) {}
    int rank() const override { return m_rank; }
    int ranks() const override { return int(m_ring.slots.size()); }
    std::vector<std::vector<char>> allgather(const std::vector<char>& mine) const override {
        m_ring.slots[size_t(m_rank)] = mine;
        m_ring.barrier.arrive_and_wait();
        std::vector<std::vector<char>> all = m_ring.slots;
        m_ring.barrier.arrive_and_wait();  // nobody writes the next round before all have read
        for (const auto& s : all) m_bytes += s.size();
        return all;
    }
    uint64_t bytesExchanged() const override { return m_bytes; }

private:
    Ring& m_ring;
    int m_rank;
    mutable uint64_t m_bytes = 0;
};

bool samePlanes(const FrameBuffers& a, const FrameBuffers& b) {
    std::vector<std::vector<float>> pa, pb;
    a.forEachPlane([&](const std::string&, int channels, const float* d) { pa.emplace_back(d, d + size_t(channels) * a.width * a.height); });
    b.forEachPlane([&](const std::string&, int channels, const float* d) { pb.emplace_back(d, d + size_t(channels) * b.width * b.height); });
    if (pa.size() != pb.size()) return false;
    for (size_t i = 0; i < pa.size(); ++i)
        if (pa[i].size() != pb[i].size() || std::memcmp(pa[i].data(), pb[i].data(), pa[i].size() * sizeof(float)) != 0) return false;
    return true;
}

void expectRanksRenderOneProcessImage(const std::string& sceneName, render::RenderOptions o, int ranks) {
    scene::SceneDesc desc = scene::loadScene(sceneName);
    desc.camera.width = 40;
    desc.camera.height = 29;  // rows that divide among neither 2 nor 3 ranks
    const scene::Scene scene(std::move(desc));
    o.quiet = true;
    o.seed = 3;
    const render::RenderResult one = render::render(scene, o);

    Ring ring(ranks);
    std::vector<ThreadRank> dist;
    for (int r = 0; r < ranks; ++r) dist.emplace_back(ring, r);
    std::vector<render::RenderResult> results(static_cast<size_t>(ranks));
    std::vector<std::thread> threads;
    for (int r = 0; r < ranks; ++r)
        threads.emplace_back([&, r] {
            render::RenderOptions mine = o;
            mine.distribution = &dist[size_t(r)];
            results[size_t(r)] = render::render(scene, mine);
        });
    for (auto& t : threads) t.join();

    const std::string what = sceneName + " " + o.method + " layers " + o.layers + " at " + std::to_string(ranks) + " ranks";
    for (int r = 0; r < ranks; ++r) {
        const render::RenderResult& res = results[size_t(r)];
        ASSERT_EQ(res.color.size(), one.color.size()) << what;
        EXPECT_EQ(std::memcmp(res.color.data(), one.color.data(), one.color.size() * sizeof(Vec3f)), 0) << what << ", rank " << r;
        EXPECT_TRUE(samePlanes(res.buffers, one.buffers)) << what << ", rank " << r;
        EXPECT_EQ(res.rays, one.rays) << what;
        EXPECT_EQ(res.sppAverage, one.sppAverage) << what;
        ASSERT_EQ(res.raysPerRank.size(), size_t(ranks)) << what;
        uint64_t sum = 0;
        for (uint64_t n : res.raysPerRank) {
            EXPECT_GT(n, 0u) << what;
            sum += n;
        }
        EXPECT_EQ(sum, one.rays) << what;
        // Every rank returns rank 0's stage times.
        EXPECT_EQ(res.seconds.get("total"), results[0].seconds.get("total")) << what;
        EXPECT_GT(dist[size_t(r)].bytesExchanged(), 0u) << what;
    }
}

TEST(Distribution, RanksRenderTheOneProcessImageForEveryMethod) {
    for (const char* method : {"mc", "aaf", "maaf", "atrous"})
        for (const char* layers : {"auto", "on"})
            for (int ranks : {2, 3}) {
                render::RenderOptions o;
                o.method = method;
                o.spp = 4;
                o.layers = layers;
                expectRanksRenderOneProcessImage("cornell", o, ranks);
            }
}

TEST(Distribution, MaafKeptRecordsAndAPinholeScene) {
    render::RenderOptions o;
    o.method = "maaf";
    o.spp = 4;
    o.maafKeepRecords = true;
    expectRanksRenderOneProcessImage("cornell", o, 2);
    o.method = "aaf";
    o.maafKeepRecords = false;
    expectRanksRenderOneProcessImage("grids", o, 3);
}

TEST(Distribution, OwnedRowsInterleave) {
    for (int ranks : {1, 2, 3, 7}) {
        int owners[50] = {};
        for (int y = 0; y < 50; ++y)
            for (int r = 0; r < ranks; ++r) owners[y] += render::ownsRow(y, r, ranks) ? 1 : 0;
        for (int y = 0; y < 50; ++y) EXPECT_EQ(owners[y], 1) << "row " << y << " at " << ranks << " ranks";
    }
}

}  // namespace

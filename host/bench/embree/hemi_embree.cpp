// The Embree 3 side of `hemi bench scale --embree` (docs/PERFORMANCE.md, "Pass 1 at scale"):
// casts the very hemisphere rays of a hemi ray file (written by `hemi bench scale --rays-dir`)
// through Embree, as single rays and as coherent 8- and 16-wide packets, on N threads, and
// prints one machine-readable line per mode. Only Embree's public API is called; nothing of
// Embree is in hemi. Built by build.sh beside this file; not part of CI.
//
// usage: hemi-embree FILE.rays [THREADS] [REPEAT]

#include <embree3/rtcore.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace {

struct Point {
  float origin[3];
  uint32_t patch;
  float frame[9];  // columns: where the hemisphere's x, y, z go
};

struct RayFile {
  std::vector<float> quads;  // 12 floats per patch
  std::vector<float> dirs;   // 3 floats per direction, in the hemisphere's frame
  std::vector<Point> points;
};

bool read_file(const char* path, RayFile& f) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  size_t at = 0;
  auto take = [&](void* dst, size_t n) {
    if (at + n > b.size()) return false;
    std::memcpy(dst, b.data() + at, n);
    at += n;
    return true;
  };
  char magic[8];
  uint32_t n = 0;
  if (!take(magic, 8) || std::memcmp(magic, "HEMIRAY1", 8) != 0) return false;
  if (!take(&n, 4)) return false;
  f.quads.resize(size_t(n) * 12);
  if (!take(f.quads.data(), f.quads.size() * 4) || !take(&n, 4)) return false;
  f.dirs.resize(size_t(n) * 3);
  if (!take(f.dirs.data(), f.dirs.size() * 4) || !take(&n, 4)) return false;
  f.points.resize(n);
  for (auto& p : f.points) {
    if (!take(p.origin, 12) || !take(&p.patch, 4) || !take(p.frame, 36)) return false;
  }
  return at == b.size();
}

// The world direction of hemisphere direction d at point p.
inline void world(const Point& p, const float* d, float* w) {
  for (int a = 0; a < 3; ++a) w[a] = p.frame[a] * d[0] + p.frame[3 + a] * d[1] + p.frame[6 + a] * d[2];
}

struct Tally {
  uint64_t hits = 0;
};

// One point's hemisphere as single rays.
void cast_single(RTCScene scene, const RayFile& f, const Point& p, float tnear, Tally& t) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  size_t n = f.dirs.size() / 3;
  for (size_t k = 0; k < n; ++k) {
    RTCRayHit rh;
    float w[3];
    world(p, &f.dirs[3 * k], w);
    rh.ray.org_x = p.origin[0];
    rh.ray.org_y = p.origin[1];
    rh.ray.org_z = p.origin[2];
    rh.ray.dir_x = w[0];
    rh.ray.dir_y = w[1];
    rh.ray.dir_z = w[2];
    rh.ray.tnear = tnear;
    rh.ray.tfar = 1e30f;
    rh.ray.mask = 0xffffffff;
    rh.ray.time = 0.f;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    t.hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }
}

// One point's hemisphere as coherent packets of W neighbouring directions.
template <int W, typename RH>
void cast_packets(RTCScene scene, const RayFile& f, const Point& p, float tnear, Tally& t,
                  void (*intersect)(const int*, RTCScene, RTCIntersectContext*, RH*)) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  size_t n = f.dirs.size() / 3;
  for (size_t k0 = 0; k0 < n; k0 += W) {
    alignas(64) RH rh;
    alignas(64) int valid[W];
    for (int i = 0; i < W; ++i) {
      size_t k = k0 + i;
      valid[i] = k < n ? -1 : 0;
      float w[3] = {0.f, 0.f, 1.f};
      if (k < n) world(p, &f.dirs[3 * k], w);
      rh.ray.org_x[i] = p.origin[0];
      rh.ray.org_y[i] = p.origin[1];
      rh.ray.org_z[i] = p.origin[2];
      rh.ray.dir_x[i] = w[0];
      rh.ray.dir_y[i] = w[1];
      rh.ray.dir_z[i] = w[2];
      rh.ray.tnear[i] = tnear;
      rh.ray.tfar[i] = 1e30f;
      rh.ray.mask[i] = 0xffffffff;
      rh.ray.time[i] = 0.f;
      rh.ray.flags[i] = 0;
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    }
    intersect(valid, scene, &ctx, &rh);
    for (int i = 0; i < W; ++i) t.hits += valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
  }
}

void intersect8(const int* v, RTCScene s, RTCIntersectContext* c, RTCRayHit8* r) { rtcIntersect8(v, s, c, r); }
void intersect16(const int* v, RTCScene s, RTCIntersectContext* c, RTCRayHit16* r) { rtcIntersect16(v, s, c, r); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: hemi-embree FILE.rays [THREADS] [REPEAT]\n");
    return 2;
  }
  int threads = argc > 2 ? std::atoi(argv[2]) : int(std::thread::hardware_concurrency());
  int repeat = argc > 3 ? std::atoi(argv[3]) : 1;
  if (threads < 1) threads = 1;
  if (repeat < 1) repeat = 1;
  RayFile f;
  if (!read_file(argv[1], f)) {
    std::fprintf(stderr, "hemi-embree: %s is not a hemi ray file (HEMIRAY1)\n", argv[1]);
    return 1;
  }
  RTCDevice device = rtcNewDevice("threads=1");  // our threads cast; Embree's own pool builds
  if (!device) {
    std::fprintf(stderr, "hemi-embree: rtcNewDevice failed\n");
    return 1;
  }
  size_t patches = f.quads.size() / 12;
  auto t0 = std::chrono::steady_clock::now();
  RTCScene scene = rtcNewScene(device);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
  float* vb = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), patches * 4));
  unsigned* ib = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), patches));
  float lo = 1e30f, hi = -1e30f;
  for (size_t i = 0; i < patches * 12; ++i) {
    vb[i] = f.quads[i];
    lo = std::min(lo, f.quads[i]);
    hi = std::max(hi, f.quads[i]);
  }
  for (size_t i = 0; i < patches * 4; ++i) ib[i] = unsigned(i);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // hemi's rays start on their patch and skip it by id; Embree skips it by distance
  float tnear = 1e-5f * (hi - lo);
  size_t rays = f.points.size() * (f.dirs.size() / 3);
  const char* modes[] = {"single", "packet8", "packet16"};
  for (int mode = 0; mode < 3; ++mode) {
    double best = 1e30;
    uint64_t hits = 0;
    for (int r = 0; r < repeat; ++r) {
      std::atomic<size_t> next{0};
      std::vector<Tally> tally(threads);
      auto start = std::chrono::steady_clock::now();
      std::vector<std::thread> pool;
      for (int th = 0; th < threads; ++th) {
        pool.emplace_back([&, th] {
          for (size_t i; (i = next.fetch_add(1)) < f.points.size();) {
            const Point& p = f.points[i];
            if (mode == 0) cast_single(scene, f, p, tnear, tally[th]);
            if (mode == 1) cast_packets<8, RTCRayHit8>(scene, f, p, tnear, tally[th], intersect8);
            if (mode == 2) cast_packets<16, RTCRayHit16>(scene, f, p, tnear, tally[th], intersect16);
          }
        });
      }
      for (auto& t : pool) t.join();
      double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      best = std::min(best, s);
      hits = 0;
      for (auto& t : tally) hits += t.hits;
    }
    std::printf("embree mode=%s patches=%zu hemispheres=%zu threads=%d rays=%zu hits=%llu build_seconds=%.4f seconds=%.4f rays_per_second=%.0f\n",
                modes[mode], patches, f.points.size(), threads, rays, (unsigned long long)hits, build, best,
                double(rays) / best);
    std::fflush(stdout);
  }
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  return 0;
}

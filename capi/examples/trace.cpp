// octoray from C++: the same job (job.h compiles as C++), plus the scene held by a
// std::unique_ptr with octoray_scene_free as its deleter, as a C++ renderer would.
#include <cstring>
#include <memory>
#include <vector>

#include "job.h"

using ScenePtr = std::unique_ptr<OctorayScene, decltype(&octoray_scene_free)>;

int main(int argc, char **argv) {
  // `trace-cpp demo DIR TIER WIDTH [PPM]`: the demo's exported scene, as trace.c.
  if (argc > 4 && std::strcmp(argv[1], "demo") == 0) {
    return run_demo(argv[2], static_cast<uint32_t>(std::atoi(argv[3])),
                    static_cast<uint32_t>(std::atoi(argv[4])), argc > 5 ? argv[5] : nullptr);
  }
  uint32_t tier = argc > 1 ? static_cast<uint32_t>(std::atoi(argv[1]))
                             : static_cast<uint32_t>(OCTORAY_TIER_WATERTIGHT);
  int status = run_job(tier);
  // RAII: the unknown tier is refused; a valid scene is freed when it leaves scope.
  OctorayScene *raw = nullptr;
  if (octoray_scene_new(99, &raw) != OCTORAY_STATUS_INVALID_ARGUMENT || raw != nullptr) return 1;
  check(octoray_scene_new(tier, &raw), "octoray_scene_new");
  ScenePtr scene(raw, &octoray_scene_free);
  std::vector<OctorayRay> rays(3, camera(0));
  std::vector<OctorayHit> hits(rays.size());
  check(octoray_closest(scene.get(), rays.data(), rays.size(), ~0u, hits.data()), "octoray_closest");
  for (const OctorayHit &h : hits) {
    if (h.prim != OCTORAY_NO_HIT) return 1;  // an empty scene hits nothing
  }
  return status;
}

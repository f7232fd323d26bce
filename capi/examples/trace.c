/* octoray from C.
 *   trace [TIER]                      the job of job.h (TIER: 0 standard, 1 watertight, 2 exact;
 *                                     default 1)
 *   trace demo DIR TIER WIDTH [PPM]   renders the demo's scene exported by
 *                                     `render --export DIR` and prints its primary-hit digest */
#include "job.h"

int main(int argc, char **argv) {
  if (argc > 4 && strcmp(argv[1], "demo") == 0) {
    return run_demo(argv[2], (uint32_t)atoi(argv[3]), (uint32_t)atoi(argv[4]),
                    argc > 5 ? argv[5] : NULL);
  }
  uint32_t tier = argc > 1 ? (uint32_t)atoi(argv[1]) : (uint32_t)OCTORAY_TIER_WATERTIGHT;
  return run_job(tier);
}

/* octoray from C: the job of job.h at the tier named on the command line (0 standard,
 * 1 watertight, 2 exact; default 1). */
#include "job.h"

int main(int argc, char **argv) {
  uint32_t tier = argc > 1 ? (uint32_t)atoi(argv[1]) : (uint32_t)OCTORAY_TIER_WATERTIGHT;
  return run_job(tier);
}

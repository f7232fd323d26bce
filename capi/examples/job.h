/* The C examples' job, in the subset of C that C++ also compiles: a scene of a terrain mesh
 * placed nine times (scaled, one mirrored) and a set of spheres, a 64 x 48 camera, closest hits
 * through the ray-array, single-ray and 8/16-ray packet calls (which must agree), shadow rays,
 * the scene stored and loaded back (the same answers), two failures with their messages, and a
 * digest of every answer. capi/examples/digest.rs does the same through the Rust API and must
 * print the same line (.ci/capi.sh compares them). Build with -ffp-contract=off: the camera's
 * arithmetic must round as Rust's does. */
#ifndef OCTORAY_EXAMPLE_JOB_H
#define OCTORAY_EXAMPLE_JOB_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "octoray.h"

#define GRID 24
#define WIDTH 64
#define HEIGHT 48
#define RAYS (WIDTH * HEIGHT)

/* Stops the program with the call's message when a call fails. */
static void check(enum OctorayStatus s, const char *what) {
  if (s != OCTORAY_STATUS_OK) {
    fprintf(stderr, "%s failed (%d): %s\n", what, (int)s, octoray_last_error());
    exit(1);
  }
}

/* FNV-1a over 32-bit words, little-endian bytes. */
static void fnv_word(uint64_t *h, uint32_t w) {
  for (int i = 0; i < 4; i++) {
    *h = (*h ^ ((w >> (8 * i)) & 0xff)) * 0x100000001b3ull;
  }
}

static uint32_t bits(float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  return u;
}

static void fnv_hit(uint64_t *h, const OctorayHit *hit) {
  fnv_word(h, bits(hit->t));
  fnv_word(h, bits(hit->u));
  fnv_word(h, bits(hit->v));
  fnv_word(h, hit->prim);
  fnv_word(h, hit->geom);
  fnv_word(h, hit->inst);
}

static int same_hit(const OctorayHit *a, const OctorayHit *b) {
  return bits(a->t) == bits(b->t) && bits(a->u) == bits(b->u) && bits(a->v) == bits(b->v) &&
         a->prim == b->prim && a->geom == b->geom && a->inst == b->inst;
}

/* The scene: a GRID x GRID terrain (heights in quarter steps), its nine placements, four
 * spheres (mask 2; the terrain's instances have mask 1). */
static OctorayScene *build(uint32_t tier) {
  static float vertices[(GRID + 1) * (GRID + 1) * 3];
  static uint32_t indices[GRID * GRID * 6];
  for (int z = 0; z <= GRID; z++) {
    for (int x = 0; x <= GRID; x++) {
      float *v = &vertices[3 * (z * (GRID + 1) + x)];
      v[0] = (float)x;
      v[1] = (float)((x * 7 + z * 13) % 5) * 0.25f;
      v[2] = (float)z;
    }
  }
  for (int z = 0; z < GRID; z++) {
    for (int x = 0; x < GRID; x++) {
      uint32_t a = (uint32_t)(z * (GRID + 1) + x), b = a + 1, c = a + GRID + 2, d = a + GRID + 1;
      uint32_t *t = &indices[6 * (z * GRID + x)];
      t[0] = a; t[1] = b; t[2] = c;
      t[3] = a; t[4] = c; t[5] = d;
    }
  }
  float spheres[16];
  for (int k = 0; k < 4; k++) {
    spheres[4 * k + 0] = (float)(k * 9 - 12);
    spheres[4 * k + 1] = 6.0f;
    spheres[4 * k + 2] = 10.0f;
    spheres[4 * k + 3] = 2.0f + 0.5f * (float)k;
  }
  OctorayScene *scene = NULL;
  uint32_t terrain, balls, inst;
  check(octoray_scene_new(tier, &scene), "octoray_scene_new");
  check(octoray_scene_add_mesh(scene, vertices, (GRID + 1) * (GRID + 1), indices, GRID * GRID * 2,
                               &terrain),
        "octoray_scene_add_mesh");
  check(octoray_scene_add_spheres(scene, spheres, 4, &balls), "octoray_scene_add_spheres");
  for (int i = 0; i < 9; i++) {
    float s = (i % 2 == 0) ? 1.0f : 0.5f;
    float mirror = (i == 4) ? -1.0f : 1.0f;
    /* Row-major [A | b], object to world. */
    float m[12] = {mirror * s, 0.0f, 0.0f, (float)((i % 3) * 30 - 45),
                   0.0f,       s,    0.0f, -2.0f,
                   0.0f,       0.0f, s,    (float)((i / 3) * 30 - 20)};
    check(octoray_scene_add_instance(scene, &terrain, 1, m, 1, &inst), "octoray_scene_add_instance");
  }
  check(octoray_scene_add_instance(scene, &balls, 1, NULL, 2, &inst), "octoray_scene_add_instance");
  check(octoray_scene_commit(scene), "octoray_scene_commit");
  return scene;
}

/* Camera ray k: from above and behind the field, looking along +z and down. */
static OctorayRay camera(int k) {
  OctorayRay r;
  float dx = ((float)(k % WIDTH) + 0.5f) / 32.0f - 1.0f;
  float dy = ((float)(k / WIDTH) + 0.5f) / 24.0f - 1.0f;
  r.org[0] = 0.0f; r.org[1] = 25.0f; r.org[2] = -60.0f;
  r.dir[0] = dx; r.dir[1] = -0.35f - 0.3f * dy; r.dir[2] = 1.0f;
  r.t_min = 0.0f;
  r.t_max = INFINITY;
  return r;
}

/* Runs the job on `tier`, printing one line; returns the process's exit status. */
static int run_job(uint32_t tier) {
  static OctorayRay rays[RAYS], shadow[RAYS];
  static OctorayHit hits[RAYS], again[RAYS];
  static uint8_t blocked[RAYS];
  const float light[3] = {20.0f, 60.0f, -10.0f};
  OctorayScene *scene = build(tier);
  int mismatches = 0, hit_count = 0, shadowed = 0;
  for (int k = 0; k < RAYS; k++) rays[k] = camera(k);
  check(octoray_closest(scene, rays, RAYS, ~0u, hits), "octoray_closest");

  /* Single rays and packets give the same answers as the array call. */
  for (int k = 0; k < RAYS; k++) {
    OctorayHit one;
    check(octoray_closest1(scene, &rays[k], ~0u, &one), "octoray_closest1");
    mismatches += !same_hit(&one, &hits[k]);
  }
  for (int p = 0; p < RAYS; p += 16) {
    OctorayRay8 r8[2];
    OctorayRay16 r16;
    OctorayHit8 h8[2];
    OctorayHit16 h16;
    for (int i = 0; i < 16; i++) {
      const OctorayRay *r = &rays[p + i];
      for (int a = 0; a < 3; a++) {
        r8[i / 8].org[a][i % 8] = r->org[a];
        r8[i / 8].dir[a][i % 8] = r->dir[a];
        r16.org[a][i] = r->org[a];
        r16.dir[a][i] = r->dir[a];
      }
      r8[i / 8].t_min[i % 8] = r16.t_min[i] = r->t_min;
      r8[i / 8].t_max[i % 8] = r16.t_max[i] = r->t_max;
    }
    check(octoray_closest8(scene, &r8[0], ~0u, &h8[0]), "octoray_closest8");
    check(octoray_closest8(scene, &r8[1], ~0u, &h8[1]), "octoray_closest8");
    check(octoray_closest16(scene, &r16, ~0u, &h16), "octoray_closest16");
    for (int i = 0; i < 16; i++) {
      const OctorayHit8 *e = &h8[i / 8];
      int j = i % 8;
      OctorayHit a = {e->t[j], e->u[j], e->v[j], e->prim[j], e->geom[j], e->inst[j]};
      OctorayHit b = {h16.t[i], h16.u[i], h16.v[i], h16.prim[i], h16.geom[i], h16.inst[i]};
      mismatches += !same_hit(&a, &hits[p + i]) + !same_hit(&b, &hits[p + i]);
    }
  }

  /* Shadow rays from every hit toward the light. */
  int n = 0;
  for (int k = 0; k < RAYS; k++) {
    if (hits[k].prim == OCTORAY_NO_HIT) continue;
    hit_count++;
    OctorayRay s;
    for (int a = 0; a < 3; a++) {
      s.org[a] = rays[k].org[a] + rays[k].dir[a] * hits[k].t;
      s.dir[a] = light[a] - s.org[a];
    }
    s.t_min = 1e-3f;
    s.t_max = 1.0f;
    shadow[n++] = s;
  }
  check(octoray_occluded(scene, shadow, (size_t)n, ~0u, blocked), "octoray_occluded");
  for (int k = 0; k < n; k++) {
    uint8_t one;
    check(octoray_occluded1(scene, &shadow[k], ~0u, &one), "octoray_occluded1");
    mismatches += one != blocked[k];
    shadowed += blocked[k];
  }

  /* Every hit along each camera ray, three at a time: the first at the closest hit's t. */
  int along = 0;
  static OctorayHit all[RAYS * 8];
  for (int k = 0; k < RAYS; k++) {
    OctorayHit page[3], last;
    const OctorayHit *after = NULL;
    size_t stored = 0;
    uint8_t complete = 0;
    int first = 1;
    do {
      check(octoray_all_hits1(scene, &rays[k], ~0u, after, page, 3, &stored, &complete),
            "octoray_all_hits1");
      for (size_t i = 0; i < stored; i++) {
        if (first) mismatches += hits[k].prim == OCTORAY_NO_HIT || bits(page[i].t) != bits(hits[k].t);
        first = 0;
        if (along < RAYS * 8) all[along] = page[i];
        along++;
      }
      if (stored > 0) last = page[stored - 1];
      after = &last;
    } while (!complete);
    mismatches += first && hits[k].prim != OCTORAY_NO_HIT;
  }

  /* The closest point to each shadow ray's origin lifted by 1.5: its point, distance and place. */
  static OctorayPointHit near[RAYS];
  for (int k = 0; k < n; k++) {
    const float p[3] = {shadow[k].org[0], shadow[k].org[1] + 1.5f, shadow[k].org[2]};
    check(octoray_closest_point1(scene, p, INFINITY, ~0u, &near[k]), "octoray_closest_point1");
    mismatches += near[k].prim == OCTORAY_NO_HIT || !(near[k].dist <= 1.5f);
  }

  /* Stored and loaded back: the same answers. */
  size_t len = 0;
  check(octoray_scene_store(scene, NULL, 0, &len), "octoray_scene_store");
  uint8_t *bytes = (uint8_t *)malloc(len);
  check(octoray_scene_store(scene, bytes, len, &len), "octoray_scene_store");
  OctorayScene *loaded = NULL;
  check(octoray_scene_load(bytes, len, tier, &loaded), "octoray_scene_load");
  check(octoray_closest(loaded, rays, RAYS, ~0u, again), "octoray_closest (loaded)");
  for (int k = 0; k < RAYS; k++) mismatches += !same_hit(&again[k], &hits[k]);
  /* A corrupted section length is refused with a message; a corrupted byte anywhere is a
   * valid scene or an error, never a crash. */
  OctorayScene *bad = NULL;
  bytes[8] ^= 0x40;
  int refused = octoray_scene_load(bytes, len, tier, &bad) == OCTORAY_STATUS_INVALID_SCENE &&
                strlen(octoray_last_error()) > 0;
  bytes[8] ^= 0x40;
  bytes[len / 2] ^= 0x40;
  if (octoray_scene_load(bytes, len, tier, &bad) == OCTORAY_STATUS_OK) octoray_scene_free(bad);
  free(bytes);
  /* An index past the vertices: an error with a message. */
  const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint32_t wrong[3] = {0, 1, 3};
  uint32_t geom;
  OctorayScene *fresh = NULL;
  check(octoray_scene_new(tier, &fresh), "octoray_scene_new");
  enum OctorayStatus e = octoray_scene_add_mesh(fresh, tri, 3, wrong, 1, &geom);
  refused = refused && e == OCTORAY_STATUS_INVALID_ARGUMENT && strlen(octoray_last_error()) > 0;
  octoray_scene_free(fresh);
  octoray_scene_free(loaded);
  octoray_scene_free(scene);

  uint64_t digest = 0xcbf29ce484222325ull;
  for (int k = 0; k < RAYS; k++) fnv_hit(&digest, &hits[k]);
  for (int k = 0; k < n; k++) fnv_word(&digest, blocked[k]);
  for (int k = 0; k < along && k < RAYS * 8; k++) fnv_hit(&digest, &all[k]);
  for (int k = 0; k < n; k++) {
    for (int a = 0; a < 3; a++) fnv_word(&digest, bits(near[k].point[a]));
    fnv_word(&digest, bits(near[k].dist));
    fnv_word(&digest, bits(near[k].u));
    fnv_word(&digest, bits(near[k].v));
    fnv_word(&digest, near[k].prim);
    fnv_word(&digest, near[k].geom);
    fnv_word(&digest, near[k].inst);
  }
  printf("tier %u: %d rays, %d hit, %d in shadow, %d hits along them, %d closest points, digest "
         "0x%016llx\n",
         tier, RAYS, hit_count, shadowed, along, n, (unsigned long long)digest);
  if (mismatches != 0 || !refused) {
    fprintf(stderr, "%d mismatches between the calls; bad input refused: %d\n", mismatches, refused);
    return 1;
  }
  return 0;
}

/* Reads a whole file; NULL on failure. */
static uint8_t *read_file(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  uint8_t *b = (uint8_t *)malloc(n > 0 ? (size_t)n : 1);
  if (b && n >= 0 && fread(b, 1, (size_t)n, f) == (size_t)n) {
    *len = (size_t)n;
  } else {
    free(b);
    b = NULL;
  }
  fclose(f);
  return b;
}

/* Renders the demo's scene from what `render --export DIR` wrote (DIR/scene.bin, DIR/rays.bin):
 * the primary rays in 16-ray packets, a PPM image shaded by geometry and distance
 * (DIR/render-c.ppm), and the digest of the primary hits, which the Rust demo prints too. */
static int run_demo(const char *dir, uint32_t tier, uint32_t width, const char *image) {
  char path[4096];
  size_t scene_len = 0, rays_len = 0;
  snprintf(path, sizeof path, "%s/scene.bin", dir);
  uint8_t *scene_bytes = read_file(path, &scene_len);
  snprintf(path, sizeof path, "%s/rays.bin", dir);
  uint8_t *ray_bytes = read_file(path, &rays_len);
  if (!scene_bytes || !ray_bytes || rays_len % 32 != 0 || width == 0) {
    fprintf(stderr, "cannot read %s/scene.bin and %s/rays.bin\n", dir, dir);
    return 1;
  }
  OctorayScene *scene = NULL;
  check(octoray_scene_load(scene_bytes, scene_len, tier, &scene), "octoray_scene_load");
  free(scene_bytes);
  size_t n = rays_len / 32, height = n / width;
  OctorayRay *rays = (OctorayRay *)malloc(n * sizeof(OctorayRay));
  OctorayHit *hits = (OctorayHit *)malloc(n * sizeof(OctorayHit));
  for (size_t k = 0; k < n; k++) memcpy(&rays[k], ray_bytes + 32 * k, 32); /* little-endian */
  free(ray_bytes);
  for (size_t p = 0; p < n; p += 16) {
    OctorayRay16 r;
    OctorayHit16 h;
    for (int i = 0; i < 16; i++) {
      /* Past the end: an empty range, a miss. */
      OctorayRay q = p + i < n ? rays[p + i] : rays[0];
      if (p + i >= n) { q.t_min = 1.0f; q.t_max = 0.0f; }
      for (int a = 0; a < 3; a++) { r.org[a][i] = q.org[a]; r.dir[a][i] = q.dir[a]; }
      r.t_min[i] = q.t_min;
      r.t_max[i] = q.t_max;
    }
    check(octoray_closest16(scene, &r, ~0u, &h), "octoray_closest16");
    for (int i = 0; i < 16 && p + i < n; i++) {
      OctorayHit e = {h.t[i], h.u[i], h.v[i], h.prim[i], h.geom[i], h.inst[i]};
      hits[p + i] = e;
    }
  }
  uint64_t digest = 0xcbf29ce484222325ull;
  size_t hit_count = 0;
  FILE *ppm = image ? fopen(image, "wb") : NULL;
  if (ppm) fprintf(ppm, "P6 %u %zu 255\n", width, height);
  for (size_t k = 0; k < n; k++) {
    fnv_hit(&digest, &hits[k]);
    unsigned char rgb[3] = {200, 215, 235};
    if (hits[k].prim != OCTORAY_NO_HIT) {
      hit_count++;
      float fade = 1.0f / (1.0f + 0.02f * hits[k].t);
      uint32_t g = hits[k].geom * 2654435761u;
      for (int c = 0; c < 3; c++) {
        rgb[c] = (unsigned char)((float)(64 + ((g >> (8 * c)) & 127)) * fade + 40.0f);
      }
    }
    if (ppm && k < width * height) fwrite(rgb, 1, 3, ppm);
  }
  if (ppm) fclose(ppm);
  octoray_scene_free(scene);
  free(rays);
  free(hits);
  printf("demo scene, tier %u: %zu primary rays, %zu hit, digest 0x%016llx\n", tier, n, hit_count,
         (unsigned long long)digest);
  return 0;
}

#endif

/* A Float64 array output (FMI 3.0): y[i][j] = scale * p[j] * (i + 1) * t
 * for i < 2, j < 3, row-major; p is a fixed parameter array. */
#define MODEL_TOKEN "{linesim-test-array-3}"
#define NF 4
#define NFV 11
#define NI 0
#define NB 0
#define NS 0
#include <stddef.h>
static const size_t kSize[NF] = {1, 3, 6, 1};
#include "fmi3_skeleton.h"

enum { SCALE = 0, P = 1, Y = 4, TIME = 10 };

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->f[SCALE] = 1.0;
  m->f[P] = 1.0;
  m->f[P + 1] = 2.0;
  m->f[P + 2] = 3.0;
}

static void ModelOutputs(Model* m) {
  m->f[TIME] = m->time; /* the independent variable */
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) m->f[Y + 3 * i + j] = m->f[SCALE] * m->f[P + j] * (i + 1) * m->f[TIME];
}

static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
                            bool* terminate) {
  (void)early; (void)last; (void)terminate;
  /* fixedInternalStepSize = 1 ms: a step that is no whole number of them is
   * refused, by the FMU (FMI 3.0 leaves it to the FMU). */
  const double steps = h / 0.001;
  if (fabs(steps - round(steps)) > 1e-9 * steps) {
    if (c->log) c->log(c->env, fmi3Error, "logStatusError", "h is not a multiple of 1 ms");
    return fmi3Error;
  }
  c->m.time = t + h;
  c->m.f[TIME] = t + h;
  ModelOutputs(&c->m);
  return fmi3OK;
}

/* A feedthrough of every mapped FMI 3.0 type: each output is its input. */
#define MODEL_TOKEN "{linesim-test-feedthrough-3}"
#define NF 3
#define NFV 3
#define NI 2
#define NB 2
#define NS 2
#include <stddef.h>
static const size_t kSize[NF] = {1, 1, 1};
#include "fmi3_skeleton.h"

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->i[0] = -7;
  strcpy(m->s[0], "start");
}

static void ModelOutputs(Model* m) {
  m->f[2] = m->time; /* the independent variable */
  m->f[1] = m->f[0];
  m->i[1] = m->i[0];
  m->b[1] = m->b[0];
  strcpy(m->s[1], m->s[0]);
}

static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
                            bool* terminate) {
  (void)early; (void)last; (void)terminate;
  c->m.time = t + h;
  c->m.f[2] = t + h;
  ModelOutputs(&c->m);
  return fmi3OK;
}

/* Dahlquist's test equation with an input: x' = -k x + u (FMI 2.0).
 * Each doStep advances x exactly for u held over the step:
 *   x(t + h) = x e^{-k h} + u (1 - e^{-k h}) / k,
 * so with u = 0 the results are x0 e^{-k t} to rounding. */
#define MODEL_GUID "{linesim-test-dahlquist-2}"
#define NR 6
#define NI 0
#define NB 0
#define NS 0
#define MODEL_CAN_GET_SET_STATE 1
#include "fmi2_skeleton.h"

enum { X = 0, K = 1, X0 = 2, U = 3, DER_X = 4, TIME = 5 };

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->r[K] = 1.0;
  m->r[X0] = 1.0;
  m->r[X] = 1.0;
}

static void ModelOutputs(Model* m) {
  if (!m->started) m->r[X] = m->r[X0];
  m->r[DER_X] = -m->r[K] * m->r[X] + m->r[U];
}

static fmi2Status ModelStep(Instance* c, double t, double h) {
  Model* m = &c->m;
  if (h <= 0) {
    Say(c, fmi2Error, "logStatusError", "step size %g refused: must be > 0", h);
    return fmi2Error;
  }
  const double k = m->r[K];
  const double e = exp(-k * h);
  m->r[X] = m->r[X] * e + (k != 0 ? m->r[U] * (1.0 - e) / k : m->r[U] * h);
  m->r[TIME] = t + h;
  m->time = t + h;
  m->last_successful_time = t + h;
  ModelOutputs(m);
  return fmi2OK;
}

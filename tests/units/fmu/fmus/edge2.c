/* x = time, stepping up to an edge it must meet exactly (FMI 2.0): a step
 * that would pass over t_edge (t < t_edge < t + h) returns fmi2Discard with
 * nothing advanced; a step that ends on the edge, or starts at or after it,
 * is taken. The state can be saved, and any step size is accepted: what a
 * master that retries a discarded step smaller needs. */
#define MODEL_GUID "{linesim-test-edge-2}"
#define NR 2
#define NI 0
#define NB 0
#define NS 0
#define MODEL_CAN_GET_SET_STATE 1
#include "fmi2_skeleton.h"

enum { X = 0, T_EDGE = 1 };

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->r[T_EDGE] = 0.375;
}

static void ModelOutputs(Model* m) { (void)m; }

static fmi2Status ModelStep(Instance* c, double t, double h) {
  Model* m = &c->m;
  if (t < m->r[T_EDGE] && m->r[T_EDGE] < t + h) {
    m->last_successful_time = t;
    Say(c, fmi2Discard, "logStatusDiscard", "a step from %g s over %g s would pass t_edge = %g s",
        t, h, m->r[T_EDGE]);
    return fmi2Discard;
  }
  m->r[X] = t + h;
  m->time = t + h;
  m->last_successful_time = t + h;
  return fmi2OK;
}

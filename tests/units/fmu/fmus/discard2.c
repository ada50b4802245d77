/* x = time, until the step that would pass t_discard: that step returns
 * fmi2Discard, having computed up to t_discard (FMI 2.0). */
#define MODEL_GUID "{linesim-test-discard-2}"
#define NR 2
#define NI 0
#define NB 0
#define NS 0
#define MODEL_CAN_GET_SET_STATE 0
#include "fmi2_skeleton.h"

enum { X = 0, T_DISCARD = 1 };

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->r[T_DISCARD] = 0.5;
}

static void ModelOutputs(Model* m) { (void)m; }

static fmi2Status ModelStep(Instance* c, double t, double h) {
  Model* m = &c->m;
  if (t + h > m->r[T_DISCARD]) {
    m->r[X] = m->r[T_DISCARD];
    m->last_successful_time = m->r[T_DISCARD];
    Say(c, fmi2Discard, "logStatusDiscard", "cannot pass t_discard = %g", m->r[T_DISCARD]);
    return fmi2Discard;
  }
  m->r[X] = t + h;
  m->time = t + h;
  m->last_successful_time = t + h;
  return fmi2OK;
}

/* x = time, until the step that would pass t_end: that step computes up to
 * t_end and returns fmi2Discard with fmi2Terminated = true (FMI 2.0.4,
 * section 4.2.3: the slave asks to end the simulation). */
#define MODEL_GUID "{linesim-test-terminate-2}"
#define NR 2
#define NI 0
#define NB 0
#define NS 0
#define MODEL_CAN_GET_SET_STATE 1
#include "fmi2_skeleton.h"

enum { X = 0, T_END = 1 };

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->r[T_END] = 0.355;
}

static void ModelOutputs(Model* m) { (void)m; }

static fmi2Status ModelStep(Instance* c, double t, double h) {
  Model* m = &c->m;
  if (m->terminated) return fmi2Error; /* no step after the end */
  if (t + h > m->r[T_END]) {
    m->r[X] = m->r[T_END];
    m->time = m->last_successful_time = m->r[T_END];
    m->terminated = 1;
    Say(c, fmi2Discard, "logStatusDiscard", "end of the simulation at t_end = %g", m->r[T_END]);
    return fmi2Discard;
  }
  m->r[X] = t + h;
  m->time = m->last_successful_time = t + h;
  return fmi2OK;
}

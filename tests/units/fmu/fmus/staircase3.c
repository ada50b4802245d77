/* A staircase (FMI 3.0): y steps up by 1 at every multiple of `period`
 * (an event), area = the integral of y over time. Instantiated with
 * earlyReturnAllowed it returns early at each event inside a step, with
 * lastSuccessfulTime = the event time; an event at the end of a step is
 * reported as an early return with lastSuccessfulTime = t + h. A doStep
 * that does not start where the FMU is (its lastSuccessfulTime) is refused
 * with fmi3Error. At t_stop it asks to end the simulation
 * (terminateSimulation). */
#define MODEL_TOKEN "{linesim-test-staircase-3}"
#define NF 6
#define NFV 6
#define NI 0
#define NB 0
#define NS 0
#include <stddef.h>
static const size_t kSize[NF] = {1, 1, 1, 1, 1, 1};
#include "fmi3_skeleton.h"

enum { Y = 0, AREA = 1, PERIOD = 2, T_STOP = 3, EVENTS = 4, TIME = 5 };
/* Times closer than this are one time (the test's times are multiples of
 * 0.05 s, computed in doubles). */
#define SAME_TIME 1e-9

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->f[PERIOD] = 0.25;
  m->f[T_STOP] = 1e9;
}

/* The independent variable `time` is the FMU's time. */
static void ModelOutputs(Model* m) { m->f[TIME] = m->time; }

static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
                            bool* terminate) {
  Model* m = &c->m;
  if (fabs(t - m->time) > SAME_TIME) {
    char text[160];
    snprintf(text, sizeof text, "doStep from t = %.17g, but the FMU is at %.17g", t, m->time);
    if (c->log) c->log(c->env, fmi3Error, "logStatusError", text);
    return fmi3Error;
  }
  const double end = t + h;
  double now = t;
  for (;;) {
    const double te = (m->f[EVENTS] + 1) * m->f[PERIOD];
    const int at_end = fabs(te - end) <= SAME_TIME;
    if (te > end && !at_end) break;
    const double event = at_end ? end : te;
    m->f[AREA] += m->f[Y] * (event - now);
    now = event;
    m->f[Y] += 1;
    m->f[EVENTS] += 1;
    if (now >= m->f[T_STOP] - SAME_TIME) {
      *terminate = true;
      *last = now;
      m->time = now;
      return fmi3OK;
    }
    if (at_end) {
      *early = c->early_allowed;
      *last = end;
      m->time = end;
      return fmi3OK;
    }
    if (c->early_allowed) {
      *early = true;
      *last = now;
      m->time = now;
      return fmi3OK;
    }
  }
  m->f[AREA] += m->f[Y] * (end - now);
  m->time = end;
  *last = end;
  return fmi3OK;
}

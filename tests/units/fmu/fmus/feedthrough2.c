/* A feedthrough of every FMI 2.0 type: each output is its input (the
 * Real "out.a" plus the tunable parameter "offset"). */
#define MODEL_GUID "{linesim-test-feedthrough-2}"
#define NR 5
#define NI 2
#define NB 2
#define NS 2
#define MODEL_CAN_GET_SET_STATE 1
#include "fmi2_skeleton.h"

enum { A = 0, B = 1, OFFSET = 2, A_OUT = 3, B_OUT = 4 };

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->r[A] = 0.5;
  m->i[0] = 3;
  m->b[0] = 1;
  strcpy(m->s[0], "start");
}

static void ModelOutputs(Model* m) {
  m->r[A_OUT] = m->r[A] + m->r[OFFSET];
  m->r[B_OUT] = m->r[B];
  m->i[1] = m->i[0];
  m->b[1] = m->b[0];
  strcpy(m->s[1], m->s[0]);
}

static fmi2Status ModelStep(Instance* c, double t, double h) {
  c->m.time = t + h;
  c->m.last_successful_time = t + h;
  ModelOutputs(&c->m);
  return fmi2OK;
}

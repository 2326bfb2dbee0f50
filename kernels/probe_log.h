/* The probe's event log: hooks in the solver that record each step when built with ALGRAY_PROBE=1, else nothing. */
#ifndef ALGRAY_PROBE_LOG_H
#define ALGRAY_PROBE_LOG_H

#include "algray_shared.h"
#include "real.h"

/* The hooks are macros, and the log travels as an extra trailing parameter (PROBE_PARAM / PROBE_ARG), so that a
 * render build contains no trace of them: the probe runs the render's solver code with the recording added, and
 * nothing it records is computed unless it is recording. */
#if ALGRAY_PROBE
typedef struct {
  __global ProbeEvent* events;
  __global REAL* values; /* 4 per event */
  uint capacity;
  uint count; /* events offered, which may exceed capacity: the host reports the overflow */
} ProbeLog;

void probe_record(ProbeLog* log, uint kind, int count, uint decision, uint level, REAL a, REAL b, REAL c, REAL d) {
  const uint i = log->count++;
  if (i >= log->capacity) return;
  ProbeEvent e;
  e.kind = kind;
  e.count = count;
  e.decision = decision;
  e.level = level;
  log->events[i] = e;
  log->values[4 * i] = a;
  log->values[4 * i + 1] = b;
  log->values[4 * i + 2] = c;
  log->values[4 * i + 3] = d;
}

#define PROBE_PARAM , ProbeLog *probe_log
#define PROBE_ARG , probe_log
#define PROBE(kind, count, decision, level, a, b, c, d) \
  probe_record(probe_log, kind, count, decision, level, a, b, c, d)
#else
#define PROBE_PARAM
#define PROBE_ARG
#define PROBE(kind, count, decision, level, a, b, c, d) ((void)0)
#endif

/* One isolation step on the interval iso describes. */
#define PROBE_STEP(iso, count, decision, level) \
  PROBE(ALGRAY_EVENT_STEP, count, decision, (uint)(level), (iso).lo, (iso).hi, (iso).f_lo, (iso).f_hi)
/* One refinement iterate y with value fy inside the bracket [a, b]. */
#define PROBE_ITERATE(it, y, fy, a, b) PROBE(ALGRAY_EVENT_ITERATE, (int)(it), 0u, 0u, y, fy, a, b)

#endif /* ALGRAY_PROBE_LOG_H */

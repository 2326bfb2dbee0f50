/* The probe's event log: hooks in the solver that record each step when built with ALGRAY_PROBE=1, else nothing. */
#ifndef ALGRAY_PROBE_LOG_H
#define ALGRAY_PROBE_LOG_H

#include "algray_shared.h"
#include "real.h"

/* The log is a parameter of every function that records (ProbeLog* probe_log), always passed: render kernels pass
 * NO_PROBE, and with ALGRAY_PROBE 0 the hooks are ((void)probe_log), so a render build contains no trace of them.
 * The hooks are macros so that nothing they record is computed unless the probe is recording. */
typedef struct {
  __global ProbeEvent* events;
  __global REAL* values; /* 4 per event */
  uint capacity;
  uint count; /* events offered, which may exceed capacity: the host reports the overflow */
} ProbeLog;
#define NO_PROBE ((ProbeLog*)0)

#if ALGRAY_PROBE
static void probe_record(ProbeLog* log, uint kind, int count, uint decision, uint level, REAL a, REAL b, REAL c,
                         REAL d) {
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

#define PROBE(kind, count, decision, level, a, b, c, d) \
  probe_record(probe_log, kind, count, decision, level, a, b, c, d)
#else
#define PROBE(kind, count, decision, level, a, b, c, d) ((void)probe_log)
#endif

/* One isolation step on the interval iso describes. */
#define PROBE_STEP(iso, count, decision, level) \
  PROBE(ALGRAY_EVENT_STEP, count, decision, (uint)(level), (iso).lo, (iso).hi, (iso).f_lo, (iso).f_hi)
/* One refinement iterate y with value fy inside the bracket [a, b]. */
#define PROBE_ITERATE(it, y, fy, a, b) PROBE(ALGRAY_EVENT_ITERATE, (int)(it), 0u, 0u, y, fy, a, b)

#endif /* ALGRAY_PROBE_LOG_H */

/*
** l_progress.h — the progress line and Ctrl-C for long library calls made
** from Lua (polygonize, render, heightfield work).
**
** The library calls the oc_progress callback from one thread, not
** necessarily the Lua state's, so the callback touches nothing but the
** line on stderr and the interpreter's Ctrl-C flag (OCLUA_INTERRUPT),
** which cancels the work. The line appears only for work that lasts
** (half a second), so quick calls do not flicker on the terminal.
*/
#ifndef L_PROGRESS_H
#define L_PROGRESS_H

#include <signal.h>
#include <time.h>

#include "l_util.h"

typedef struct oclua_progress {
  const char *fname;
  struct timespec start;
  double base, span; /* the current phase's part of the line: [0, 1] */
  int shown;         /* percentage on the line, or -1 while nothing is shown */
  int tty;           /* stderr is a terminal: draw the line */
  volatile sig_atomic_t *stop; /* the interpreter's Ctrl-C flag, or NULL */
} oclua_progress;

/* Prepares pl and returns the callback to hand to the library (with a
** NULL fn when there is neither a terminal nor an interrupt flag). */
oc_progress oclua_progress_start(lua_State *L, oclua_progress *pl,
                                 const char *fname);
/* Reports progress from the Lua side (work done between library calls);
** returns non-zero once Ctrl-C was pressed. */
int oclua_progress_report(oclua_progress *pl, double fraction);
/* Erases the line, if one was drawn (a later phase may draw it again). */
void oclua_progress_end(oclua_progress *pl);

#endif

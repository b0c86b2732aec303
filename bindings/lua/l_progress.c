/*
** l_progress.c — the progress line and Ctrl-C for long library calls.
*/
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "l_progress.h"

#define PROGRESS_DELAY 0.5 /* seconds before a line shows */

static double seconds_since(const struct timespec *t0) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)(t.tv_sec - t0->tv_sec) +
         1e-9 * (double)(t.tv_nsec - t0->tv_nsec);
}

static int show(void *ud, double fraction) {
  oclua_progress *pl = ud;
  if (pl->stop && *pl->stop) return 1;
  if (!pl->tty) return 0;
  fraction = pl->base + pl->span * fraction;
  int pct = fraction > 0 ? (fraction < 1 ? (int)(fraction * 100) : 100) : 0;
  if (pct != pl->shown && seconds_since(&pl->start) >= PROGRESS_DELAY) {
    fprintf(stderr, "\r%s: %3d %%", pl->fname, pct);
    fflush(stderr);
    pl->shown = pct;
  }
  return 0;
}

int oclua_progress_report(oclua_progress *pl, double fraction) {
  return show(pl, fraction);
}

oc_progress oclua_progress_start(lua_State *L, oclua_progress *pl,
                                 const char *fname) {
  oc_progress pr = {NULL, NULL};
  pl->fname = fname;
  pl->base = 0, pl->span = 1;
  pl->shown = -1;
  pl->tty = isatty(2);
  pl->stop = NULL;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_INTERRUPT) == LUA_TLIGHTUSERDATA)
    pl->stop = (volatile sig_atomic_t *)lua_touserdata(L, -1);
  lua_pop(L, 1);
  if (pl->tty || pl->stop) {
    clock_gettime(CLOCK_MONOTONIC, &pl->start);
    pr.fn = show;
    pr.ud = pl;
  }
  return pr;
}

void oclua_progress_end(oclua_progress *pl) {
  if (pl->shown < 0) return;
  fprintf(stderr, "\r%*s\r", (int)strlen(pl->fname) + 8, "");
  fflush(stderr);
  pl->shown = -1;
}

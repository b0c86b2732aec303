/*
** l_image.h — the image userdata, for every binding file that returns
** images (slices now, renders later).
*/
#ifndef L_IMAGE_H
#define L_IMAGE_H

#include "l_handle.h"

#define OCLUA_IMAGE "outcrop.image"

typedef struct oclua_image {
  oclua_handle h; /* first: pins and closing (l_handle.h) */
  oc_image *img;  /* NULL while being made, or once freed */
} oclua_image;

/* Pushes an image userdata owning nothing yet: create it BEFORE making
** the oc_image, then store the image in it, so an error cannot leak. */
oclua_image *oclua_newimage(lua_State *L);
/* Raises unless idx is an open image; with pin set, pins it for the rest
** of the call (oclua_pin). */
oc_image *oclua_checkimage(lua_State *L, int idx, const char *fname, int pin);

/* outcrop.slice(node, {plane =, at =, box =, size =, palette =}) under
** the name fname, pushing the image: with a palette (given, or `stops`
** when the option is absent and stops is not NULL) the colour channels
** are the field value through it. */
int oclua_slice(lua_State *L, const char *fname, const double *stops,
                int nstops);

/* Adds outcrop.slice to the module table at the stack top and sets up
** the image metatable. */
void oclua_open_image(lua_State *L);

#endif

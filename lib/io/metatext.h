/*
** metatext.h — metadata as "key=value" lines, for the formats that keep
** text only in their ImageDescription (TIFF, JPEG).
**
** A value that holds a space, a double quote, a backslash or a control
** byte is written in double quotes with \" \\ \n \t \r and \ddd escapes,
** the way outcrop:params quotes its pairs; any other value is written as
** it is. So no value can hold a line break, and no value can forge a line
** such as "outcrop:seed=99". Readers unquote a value that starts with a
** double quote.
*/
#ifndef OC_METATEXT_H
#define OC_METATEXT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Writes the line form of `value` into out (NUL-terminated) and returns
** its length; out must hold oc_meta_quoted_size(value) bytes. */
size_t oc_meta_quoted_size(const char *value);
size_t oc_meta_quote(const char *value, char *out);

/* Calls take(ud, key, value) for every "key=value" line of `text`, values
** unquoted. Lines without '=' and badly quoted values are skipped (a
** description may hold free text too). Returns 0, or -1 when out of
** memory (nothing taken). */
int oc_meta_unfold(const char *text,
                   void (*take)(void *ud, const char *key, const char *value),
                   void *ud);

#ifdef __cplusplus
}
#endif
#endif

/* CM_API marks the functions of the public API. libcadmorph is built with hidden symbols
 * (-fvisibility=hidden), so only what carries CM_API is exported from the shared library;
 * module-internal functions stay private to it. A user's code needs no definition: on ELF
 * the attribute is the same for building and using the library. */
#ifndef CADMORPH_EXPORT_H
#define CADMORPH_EXPORT_H

#if defined(_WIN32) && !defined(CM_STATIC)
#if defined(CM_BUILDING_LIBRARY)
#define CM_API __declspec(dllexport)
#else
#define CM_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) || defined(__clang__)
#define CM_API __attribute__((visibility("default")))
#else
#define CM_API
#endif

#endif

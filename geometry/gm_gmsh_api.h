/* gm_gmsh_api: gmsh's C API (gmshc.h) reached through a table filled on
 * first use, so that a process opens libgmsh (and the hundred libraries it
 * brings: OpenCASCADE, alglib, ...) only when its scene meshes or reads a
 * gmsh or STL file.  Included after gmshc.h, each name below becomes its
 * entry in the table, so the call sites read as gmsh's own API.  A gmsh
 * function not in the table stays an undefined symbol, which the link of
 * libpointmech.so (-Wl,--no-undefined) and of every program refuses. */
#ifndef GM_GMSH_API_H
#define GM_GMSH_API_H

#include <gmshc.h>

#include "pm_dl.h"
#include "pm_error.h"

/* X(name): every function of gmshc.h the geometry modules call. */
#define GM_GMSH_API(X)                                                         \
  X(gmshFinalize)                                                              \
  X(gmshFree)                                                                  \
  X(gmshInitialize)                                                            \
  X(gmshLoggerGetLastError)                                                    \
  X(gmshModelAdd)                                                              \
  X(gmshModelGeoAddSurfaceLoop)                                                \
  X(gmshModelGeoAddVolume)                                                     \
  X(gmshModelGeoSynchronize)                                                   \
  X(gmshModelGetBoundingBox)                                                   \
  X(gmshModelGetDimension)                                                     \
  X(gmshModelGetEntities)                                                      \
  X(gmshModelGetEntitiesForPhysicalGroup)                                      \
  X(gmshModelGetEntitiesInBoundingBox)                                         \
  X(gmshModelGetPhysicalGroups)                                                \
  X(gmshModelGetPhysicalName)                                                  \
  X(gmshModelMeshClassifySurfaces)                                             \
  X(gmshModelMeshClear)                                                        \
  X(gmshModelMeshCreateGeometry)                                               \
  X(gmshModelMeshFieldAdd)                                                     \
  X(gmshModelMeshFieldSetAsBackgroundMesh)                                     \
  X(gmshModelMeshFieldSetNumber)                                               \
  X(gmshModelMeshFieldSetNumbers)                                              \
  X(gmshModelMeshGenerate)                                                     \
  X(gmshModelMeshGetElementProperties)                                         \
  X(gmshModelMeshGetElementTypes)                                              \
  X(gmshModelMeshGetElements)                                                  \
  X(gmshModelMeshGetElementsByType)                                            \
  X(gmshModelMeshGetNode)                                                      \
  X(gmshModelMeshGetNodes)                                                     \
  X(gmshModelOccAddBox)                                                        \
  X(gmshModelOccAddRectangle)                                                  \
  X(gmshModelOccSynchronize)                                                   \
  X(gmshOpen)                                                                  \
  X(gmshOptionGetNumber)                                                       \
  X(gmshOptionSetNumber)

PM_DL_TABLE(GM_GMSH_API, gm_gmsh_api_table);

extern gm_gmsh_api_table gm_gmsh_api;

/* Opens libgmsh (the soname the build found, PM_GMSH_SONAME) once per
 * process and fills the table (pm_dl_load).  need names what asked for it (a
 * file's path, or "meshing a box") in the message of PM_ERR_UNSUPPORTED when
 * the library cannot be opened or lacks a function.  gm_gmsh_begin calls it:
 * every gmsh call runs inside a session. */
pm_err gm_gmsh_api_load(const char *need);
/* The same with the library named: soname is dlopen's argument. */
pm_err gm_gmsh_api_load_from(const char *soname, const char *need);

/* gm_gmsh_api.c fills the table by these names and so sees them as gmsh
 * declares them. */
#ifndef GM_GMSH_API_IMPL
#define gmshFinalize (gm_gmsh_api.gmshFinalize)
#define gmshFree (gm_gmsh_api.gmshFree)
#define gmshInitialize (gm_gmsh_api.gmshInitialize)
#define gmshLoggerGetLastError (gm_gmsh_api.gmshLoggerGetLastError)
#define gmshModelAdd (gm_gmsh_api.gmshModelAdd)
#define gmshModelGeoAddSurfaceLoop (gm_gmsh_api.gmshModelGeoAddSurfaceLoop)
#define gmshModelGeoAddVolume (gm_gmsh_api.gmshModelGeoAddVolume)
#define gmshModelGeoSynchronize (gm_gmsh_api.gmshModelGeoSynchronize)
#define gmshModelGetBoundingBox (gm_gmsh_api.gmshModelGetBoundingBox)
#define gmshModelGetDimension (gm_gmsh_api.gmshModelGetDimension)
#define gmshModelGetEntities (gm_gmsh_api.gmshModelGetEntities)
#define gmshModelGetEntitiesForPhysicalGroup                                   \
  (gm_gmsh_api.gmshModelGetEntitiesForPhysicalGroup)
#define gmshModelGetEntitiesInBoundingBox                                      \
  (gm_gmsh_api.gmshModelGetEntitiesInBoundingBox)
#define gmshModelGetPhysicalGroups (gm_gmsh_api.gmshModelGetPhysicalGroups)
#define gmshModelGetPhysicalName (gm_gmsh_api.gmshModelGetPhysicalName)
#define gmshModelMeshClassifySurfaces                                          \
  (gm_gmsh_api.gmshModelMeshClassifySurfaces)
#define gmshModelMeshClear (gm_gmsh_api.gmshModelMeshClear)
#define gmshModelMeshCreateGeometry (gm_gmsh_api.gmshModelMeshCreateGeometry)
#define gmshModelMeshFieldAdd (gm_gmsh_api.gmshModelMeshFieldAdd)
#define gmshModelMeshFieldSetAsBackgroundMesh                                  \
  (gm_gmsh_api.gmshModelMeshFieldSetAsBackgroundMesh)
#define gmshModelMeshFieldSetNumber (gm_gmsh_api.gmshModelMeshFieldSetNumber)
#define gmshModelMeshFieldSetNumbers (gm_gmsh_api.gmshModelMeshFieldSetNumbers)
#define gmshModelMeshGenerate (gm_gmsh_api.gmshModelMeshGenerate)
#define gmshModelMeshGetElementProperties                                      \
  (gm_gmsh_api.gmshModelMeshGetElementProperties)
#define gmshModelMeshGetElementTypes (gm_gmsh_api.gmshModelMeshGetElementTypes)
#define gmshModelMeshGetElements (gm_gmsh_api.gmshModelMeshGetElements)
#define gmshModelMeshGetElementsByType                                         \
  (gm_gmsh_api.gmshModelMeshGetElementsByType)
#define gmshModelMeshGetNode (gm_gmsh_api.gmshModelMeshGetNode)
#define gmshModelMeshGetNodes (gm_gmsh_api.gmshModelMeshGetNodes)
#define gmshModelOccAddBox (gm_gmsh_api.gmshModelOccAddBox)
#define gmshModelOccAddRectangle (gm_gmsh_api.gmshModelOccAddRectangle)
#define gmshModelOccSynchronize (gm_gmsh_api.gmshModelOccSynchronize)
#define gmshOpen (gm_gmsh_api.gmshOpen)
#define gmshOptionGetNumber (gm_gmsh_api.gmshOptionGetNumber)
#define gmshOptionSetNumber (gm_gmsh_api.gmshOptionSetNumber)
#endif

#endif

/* pm_petsc_api: PETSc reached through a table filled on first use, so that
 * a process opens libpetsc (and the fifty libraries only it brings: MUMPS,
 * SuperLU, hypre, Trilinos' ML, ...) only when its run solves (a static
 * solve, implicit MPM).  Included after every PETSc header of a file, each name
 * below becomes its entry in the table: a function keeps its call syntax
 * and a variable (PETSC_COMM_WORLD) its use.  A PETSc symbol not in the
 * table stays undefined, which the link of libpointmech.so
 * (-Wl,--no-undefined) and of every program refuses. */
#ifndef PM_PETSC_API_H
#define PM_PETSC_API_H

#include <petscksp.h>
#include <petscmat.h>
#include <petscsnes.h>
#include <petscsys.h>

#include "pm_dl.h"
#include "pm_error.h"

/* X(name): every function and variable of PETSc the program uses. */
#define PM_PETSC_API(X)                                                        \
  X(ISLocalToGlobalMappingCreate)                                              \
  X(ISLocalToGlobalMappingDestroy)                                             \
  X(KSPConvergedDefault)                                                       \
  X(KSPConvergedDefaultCreate)                                                 \
  X(KSPConvergedDefaultDestroy)                                                \
  X(KSPConvergedReasons)                                                       \
  X(KSPCreate)                                                                 \
  X(KSPDestroy)                                                                \
  X(KSPGMRESSetRestart)                                                        \
  X(KSPGetConvergedReason)                                                     \
  X(KSPGetIterationNumber)                                                     \
  X(KSPGetOperators)                                                           \
  X(KSPGetPC)                                                                  \
  X(KSPGetTolerances)                                                          \
  X(KSPGetType)                                                                \
  X(KSPSetConvergenceTest)                                                     \
  X(KSPSetFromOptions)                                                         \
  X(KSPSetOperators)                                                           \
  X(KSPSetOptionsPrefix)                                                       \
  X(KSPSetPCSide)                                                              \
  X(KSPSetPostSolve)                                                           \
  X(KSPSetPreSolve)                                                            \
  X(KSPSetReusePreconditioner)                                                 \
  X(KSPSetTolerances)                                                          \
  X(KSPSetType)                                                                \
  X(KSPSetUp)                                                                  \
  X(KSPSetUpOnBlocks)                                                          \
  X(KSPSolve)                                                                  \
  X(MatAssemblyBegin)                                                          \
  X(MatAssemblyEnd)                                                            \
  X(MatCreate)                                                                 \
  X(MatCreateShell)                                                            \
  X(MatDestroy)                                                                \
  X(MatDiagonalSet)                                                            \
  X(MatGetRowIJ)                                                               \
  X(MatNullSpaceCreate)                                                        \
  X(MatNullSpaceDestroy)                                                       \
  X(MatPreallocatorPreallocate)                                                \
  X(MatRestoreRowIJ)                                                           \
  X(MatSeqAIJGetArrayRead)                                                     \
  X(MatSeqAIJGetArrayWrite)                                                    \
  X(MatSeqAIJRestoreArrayRead)                                                 \
  X(MatSeqAIJRestoreArrayWrite)                                                \
  X(MatSeqAIJSetPreallocationCSR)                                              \
  X(MatSetBlockSize)                                                           \
  X(MatSetLocalToGlobalMapping)                                                \
  X(MatSetNearNullSpace)                                                       \
  X(MatSetOption)                                                              \
  X(MatSetSizes)                                                               \
  X(MatSetType)                                                                \
  X(MatSetUp)                                                                  \
  X(MatSetValues)                                                              \
  X(MatSetValuesLocal)                                                         \
  X(MatShellGetContext)                                                        \
  X(MatShellSetOperation)                                                      \
  X(MatZeroEntries)                                                            \
  X(PCFactorSetMatSolverType)                                                  \
  X(PCMGGetLevels)                                                             \
  X(PCMGGetSmoother)                                                           \
  X(PCMGResidualDefault)                                                       \
  X(PCMGSetResidual)                                                           \
  X(PCSetFailedReason)                                                         \
  X(PCSetType)                                                                 \
  X(PCSetUseAmat)                                                              \
  X(PCShellGetContext)                                                         \
  X(PCShellSetApply)                                                           \
  X(PCShellSetContext)                                                         \
  X(PCShellSetName)                                                            \
  X(PCShellSetSetUp)                                                           \
  X(PETSC_COMM_WORLD)                                                          \
  X(PetscError)                                                                \
  X(PetscErrorMessage)                                                         \
  X(PetscFinalize)                                                             \
  X(PetscInitializeNoArguments)                                                \
  X(PetscInitialized)                                                          \
  X(PetscMPIErrorString)                                                       \
  X(PetscMallocA)                                                              \
  X(PetscMallocValidate)                                                       \
  X(PetscObjectSetOptions)                                                     \
  X(PetscObjectTypeCompare)                                                    \
  X(PetscOptionsCreate)                                                        \
  X(PetscOptionsDestroy)                                                       \
  X(PetscOptionsGetBool)                                                       \
  X(PetscOptionsGetInt)                                                        \
  X(PetscOptionsInsertString)                                                  \
  X(PetscOptionsPop)                                                           \
  X(PetscOptionsPush)                                                          \
  X(PetscPopSignalHandler)                                                     \
  X(PetscPushErrorHandler)                                                     \
  X(PetscTrFree)                                                               \
  X(SNESComputeFunction)                                                       \
  X(SNESConvergedReasons)                                                      \
  X(SNESCreate)                                                                \
  X(SNESDestroy)                                                               \
  X(SNESGetConvergedReason)                                                    \
  X(SNESGetFunction)                                                           \
  X(SNESGetIterationNumber)                                                    \
  X(SNESGetLineSearch)                                                         \
  X(SNESGetLinearSolveIterations)                                              \
  X(SNESGetSolution)                                                           \
  X(SNESLineSearchApply)                                                       \
  X(SNESLineSearchCreate)                                                      \
  X(SNESLineSearchDestroy)                                                     \
  X(SNESLineSearchGetLambda)                                                   \
  X(SNESLineSearchGetNorms)                                                    \
  X(SNESLineSearchGetReason)                                                   \
  X(SNESLineSearchGetSNES)                                                     \
  X(SNESLineSearchGetVecs)                                                     \
  X(SNESLineSearchPreCheck)                                                    \
  X(SNESLineSearchSetFunction)                                                 \
  X(SNESLineSearchSetLambda)                                                   \
  X(SNESLineSearchSetNorms)                                                    \
  X(SNESLineSearchSetPreCheck)                                                 \
  X(SNESLineSearchSetReason)                                                   \
  X(SNESLineSearchSetSNES)                                                     \
  X(SNESLineSearchSetTolerances)                                               \
  X(SNESLineSearchSetType)                                                     \
  X(SNESLineSearchShellSetUserFunc)                                            \
  X(SNESSetConvergenceTest)                                                    \
  X(SNESSetFromOptions)                                                        \
  X(SNESSetFunction)                                                           \
  X(SNESSetFunctionDomainError)                                                \
  X(SNESSetJacobian)                                                           \
  X(SNESSetKSP)                                                                \
  X(SNESSetLagPreconditioner)                                                  \
  X(SNESSetOptionsPrefix)                                                      \
  X(SNESSetTolerances)                                                         \
  X(SNESSetType)                                                               \
  X(SNESSolve)                                                                 \
  X(VecAXPY)                                                                   \
  X(VecCopy)                                                                   \
  X(VecCreateGhost)                                                            \
  X(VecCreateMPI)                                                              \
  X(VecCreateSeq)                                                              \
  X(VecDestroy)                                                                \
  X(VecDot)                                                                    \
  X(VecDuplicate)                                                              \
  X(VecGetArray)                                                               \
  X(VecGetArrayRead)                                                           \
  X(VecGetArrayWrite)                                                          \
  X(VecGhostGetLocalForm)                                                      \
  X(VecGhostRestoreLocalForm)                                                  \
  X(VecGhostUpdateBegin)                                                       \
  X(VecGhostUpdateEnd)                                                         \
  X(VecNorm)                                                                   \
  X(VecPointwiseMult)                                                          \
  X(VecRestoreArray)                                                           \
  X(VecRestoreArrayRead)                                                       \
  X(VecRestoreArrayWrite)                                                      \
  X(VecWAXPY)

/* Each entry is the address of its symbol: a function's or a variable's. */
PM_DL_TABLE(PM_PETSC_API, pm_petsc_api_table);

extern pm_petsc_api_table pm_petsc_api;

/* Opens libpetsc (PM_PETSC_SONAME, the one the build found) once per
 * process and fills the table (pm_dl_load); need names what asked for it.
 * pm_petsc_init calls it, and every PETSc user calls pm_petsc_init. */
pm_err pm_petsc_api_load(const char *need);

/* pm_petsc_api.c fills the table by these names and so sees them as PETSc
 * declares them. */
#ifndef PM_PETSC_API_IMPL
#define ISLocalToGlobalMappingCreate                                           \
  (*pm_petsc_api.ISLocalToGlobalMappingCreate)
#define ISLocalToGlobalMappingDestroy                                          \
  (*pm_petsc_api.ISLocalToGlobalMappingDestroy)
#define KSPConvergedDefault (*pm_petsc_api.KSPConvergedDefault)
#define KSPConvergedDefaultCreate (*pm_petsc_api.KSPConvergedDefaultCreate)
#define KSPConvergedDefaultDestroy (*pm_petsc_api.KSPConvergedDefaultDestroy)
#define KSPConvergedReasons (*pm_petsc_api.KSPConvergedReasons)
#define KSPCreate (*pm_petsc_api.KSPCreate)
#define KSPDestroy (*pm_petsc_api.KSPDestroy)
#define KSPGMRESSetRestart (*pm_petsc_api.KSPGMRESSetRestart)
#define KSPGetConvergedReason (*pm_petsc_api.KSPGetConvergedReason)
#define KSPGetIterationNumber (*pm_petsc_api.KSPGetIterationNumber)
#define KSPGetOperators (*pm_petsc_api.KSPGetOperators)
#define KSPGetPC (*pm_petsc_api.KSPGetPC)
#define KSPGetTolerances (*pm_petsc_api.KSPGetTolerances)
#define KSPGetType (*pm_petsc_api.KSPGetType)
#define KSPSetConvergenceTest (*pm_petsc_api.KSPSetConvergenceTest)
#define KSPSetFromOptions (*pm_petsc_api.KSPSetFromOptions)
#define KSPSetOperators (*pm_petsc_api.KSPSetOperators)
#define KSPSetOptionsPrefix (*pm_petsc_api.KSPSetOptionsPrefix)
#define KSPSetPCSide (*pm_petsc_api.KSPSetPCSide)
#define KSPSetPostSolve (*pm_petsc_api.KSPSetPostSolve)
#define KSPSetPreSolve (*pm_petsc_api.KSPSetPreSolve)
#define KSPSetReusePreconditioner (*pm_petsc_api.KSPSetReusePreconditioner)
#define KSPSetTolerances (*pm_petsc_api.KSPSetTolerances)
#define KSPSetType (*pm_petsc_api.KSPSetType)
#define KSPSetUp (*pm_petsc_api.KSPSetUp)
#define KSPSetUpOnBlocks (*pm_petsc_api.KSPSetUpOnBlocks)
#define KSPSolve (*pm_petsc_api.KSPSolve)
#define MatAssemblyBegin (*pm_petsc_api.MatAssemblyBegin)
#define MatAssemblyEnd (*pm_petsc_api.MatAssemblyEnd)
#define MatCreate (*pm_petsc_api.MatCreate)
#define MatCreateShell (*pm_petsc_api.MatCreateShell)
#define MatDestroy (*pm_petsc_api.MatDestroy)
#define MatDiagonalSet (*pm_petsc_api.MatDiagonalSet)
#define MatGetRowIJ (*pm_petsc_api.MatGetRowIJ)
#define MatNullSpaceCreate (*pm_petsc_api.MatNullSpaceCreate)
#define MatNullSpaceDestroy (*pm_petsc_api.MatNullSpaceDestroy)
#define MatPreallocatorPreallocate (*pm_petsc_api.MatPreallocatorPreallocate)
#define MatRestoreRowIJ (*pm_petsc_api.MatRestoreRowIJ)
#define MatSeqAIJGetArrayRead (*pm_petsc_api.MatSeqAIJGetArrayRead)
#define MatSeqAIJGetArrayWrite (*pm_petsc_api.MatSeqAIJGetArrayWrite)
#define MatSeqAIJRestoreArrayRead (*pm_petsc_api.MatSeqAIJRestoreArrayRead)
#define MatSeqAIJRestoreArrayWrite (*pm_petsc_api.MatSeqAIJRestoreArrayWrite)
#define MatSeqAIJSetPreallocationCSR                                           \
  (*pm_petsc_api.MatSeqAIJSetPreallocationCSR)
#define MatSetBlockSize (*pm_petsc_api.MatSetBlockSize)
#define MatSetLocalToGlobalMapping (*pm_petsc_api.MatSetLocalToGlobalMapping)
#define MatSetNearNullSpace (*pm_petsc_api.MatSetNearNullSpace)
#define MatSetOption (*pm_petsc_api.MatSetOption)
#define MatSetSizes (*pm_petsc_api.MatSetSizes)
#define MatSetType (*pm_petsc_api.MatSetType)
#define MatSetUp (*pm_petsc_api.MatSetUp)
#define MatSetValues (*pm_petsc_api.MatSetValues)
#define MatSetValuesLocal (*pm_petsc_api.MatSetValuesLocal)
#define MatShellGetContext (*pm_petsc_api.MatShellGetContext)
#define MatShellSetOperation (*pm_petsc_api.MatShellSetOperation)
#define MatZeroEntries (*pm_petsc_api.MatZeroEntries)
#define PCFactorSetMatSolverType (*pm_petsc_api.PCFactorSetMatSolverType)
#define PCMGGetLevels (*pm_petsc_api.PCMGGetLevels)
#define PCMGGetSmoother (*pm_petsc_api.PCMGGetSmoother)
#define PCMGResidualDefault (*pm_petsc_api.PCMGResidualDefault)
#define PCMGSetResidual (*pm_petsc_api.PCMGSetResidual)
#define PCSetFailedReason (*pm_petsc_api.PCSetFailedReason)
#define PCSetType (*pm_petsc_api.PCSetType)
#define PCSetUseAmat (*pm_petsc_api.PCSetUseAmat)
#define PCShellGetContext (*pm_petsc_api.PCShellGetContext)
#define PCShellSetApply (*pm_petsc_api.PCShellSetApply)
#define PCShellSetContext (*pm_petsc_api.PCShellSetContext)
#define PCShellSetName (*pm_petsc_api.PCShellSetName)
#define PCShellSetSetUp (*pm_petsc_api.PCShellSetSetUp)
#define PETSC_COMM_WORLD (*pm_petsc_api.PETSC_COMM_WORLD)
#define PetscError (*pm_petsc_api.PetscError)
#define PetscErrorMessage (*pm_petsc_api.PetscErrorMessage)
#define PetscFinalize (*pm_petsc_api.PetscFinalize)
#define PetscInitializeNoArguments (*pm_petsc_api.PetscInitializeNoArguments)
#define PetscInitialized (*pm_petsc_api.PetscInitialized)
#define PetscMPIErrorString (*pm_petsc_api.PetscMPIErrorString)
#define PetscMallocA (*pm_petsc_api.PetscMallocA)
#define PetscMallocValidate (*pm_petsc_api.PetscMallocValidate)
#define PetscObjectSetOptions (*pm_petsc_api.PetscObjectSetOptions)
#define PetscObjectTypeCompare (*pm_petsc_api.PetscObjectTypeCompare)
#define PetscOptionsCreate (*pm_petsc_api.PetscOptionsCreate)
#define PetscOptionsDestroy (*pm_petsc_api.PetscOptionsDestroy)
#define PetscOptionsGetBool (*pm_petsc_api.PetscOptionsGetBool)
#define PetscOptionsGetInt (*pm_petsc_api.PetscOptionsGetInt)
#define PetscOptionsInsertString (*pm_petsc_api.PetscOptionsInsertString)
#define PetscOptionsPop (*pm_petsc_api.PetscOptionsPop)
#define PetscOptionsPush (*pm_petsc_api.PetscOptionsPush)
#define PetscPopSignalHandler (*pm_petsc_api.PetscPopSignalHandler)
#define PetscPushErrorHandler (*pm_petsc_api.PetscPushErrorHandler)
#define PetscTrFree (*pm_petsc_api.PetscTrFree)
#define SNESComputeFunction (*pm_petsc_api.SNESComputeFunction)
#define SNESConvergedReasons (*pm_petsc_api.SNESConvergedReasons)
#define SNESCreate (*pm_petsc_api.SNESCreate)
#define SNESDestroy (*pm_petsc_api.SNESDestroy)
#define SNESGetConvergedReason (*pm_petsc_api.SNESGetConvergedReason)
#define SNESGetFunction (*pm_petsc_api.SNESGetFunction)
#define SNESGetIterationNumber (*pm_petsc_api.SNESGetIterationNumber)
#define SNESGetLineSearch (*pm_petsc_api.SNESGetLineSearch)
#define SNESGetLinearSolveIterations                                           \
  (*pm_petsc_api.SNESGetLinearSolveIterations)
#define SNESGetSolution (*pm_petsc_api.SNESGetSolution)
#define SNESLineSearchApply (*pm_petsc_api.SNESLineSearchApply)
#define SNESLineSearchCreate (*pm_petsc_api.SNESLineSearchCreate)
#define SNESLineSearchDestroy (*pm_petsc_api.SNESLineSearchDestroy)
#define SNESLineSearchGetLambda (*pm_petsc_api.SNESLineSearchGetLambda)
#define SNESLineSearchGetNorms (*pm_petsc_api.SNESLineSearchGetNorms)
#define SNESLineSearchGetReason (*pm_petsc_api.SNESLineSearchGetReason)
#define SNESLineSearchGetSNES (*pm_petsc_api.SNESLineSearchGetSNES)
#define SNESLineSearchGetVecs (*pm_petsc_api.SNESLineSearchGetVecs)
#define SNESLineSearchPreCheck (*pm_petsc_api.SNESLineSearchPreCheck)
#define SNESLineSearchSetFunction (*pm_petsc_api.SNESLineSearchSetFunction)
#define SNESLineSearchSetLambda (*pm_petsc_api.SNESLineSearchSetLambda)
#define SNESLineSearchSetNorms (*pm_petsc_api.SNESLineSearchSetNorms)
#define SNESLineSearchSetPreCheck (*pm_petsc_api.SNESLineSearchSetPreCheck)
#define SNESLineSearchSetReason (*pm_petsc_api.SNESLineSearchSetReason)
#define SNESLineSearchSetSNES (*pm_petsc_api.SNESLineSearchSetSNES)
#define SNESLineSearchSetTolerances (*pm_petsc_api.SNESLineSearchSetTolerances)
#define SNESLineSearchSetType (*pm_petsc_api.SNESLineSearchSetType)
#define SNESLineSearchShellSetUserFunc                                         \
  (*pm_petsc_api.SNESLineSearchShellSetUserFunc)
#define SNESSetConvergenceTest (*pm_petsc_api.SNESSetConvergenceTest)
#define SNESSetFromOptions (*pm_petsc_api.SNESSetFromOptions)
#define SNESSetFunction (*pm_petsc_api.SNESSetFunction)
#define SNESSetFunctionDomainError (*pm_petsc_api.SNESSetFunctionDomainError)
#define SNESSetJacobian (*pm_petsc_api.SNESSetJacobian)
#define SNESSetKSP (*pm_petsc_api.SNESSetKSP)
#define SNESSetLagPreconditioner (*pm_petsc_api.SNESSetLagPreconditioner)
#define SNESSetOptionsPrefix (*pm_petsc_api.SNESSetOptionsPrefix)
#define SNESSetTolerances (*pm_petsc_api.SNESSetTolerances)
#define SNESSetType (*pm_petsc_api.SNESSetType)
#define SNESSolve (*pm_petsc_api.SNESSolve)
#define VecAXPY (*pm_petsc_api.VecAXPY)
#define VecCopy (*pm_petsc_api.VecCopy)
#define VecCreateGhost (*pm_petsc_api.VecCreateGhost)
#define VecCreateMPI (*pm_petsc_api.VecCreateMPI)
#define VecCreateSeq (*pm_petsc_api.VecCreateSeq)
#define VecDestroy (*pm_petsc_api.VecDestroy)
#define VecDot (*pm_petsc_api.VecDot)
#define VecDuplicate (*pm_petsc_api.VecDuplicate)
#define VecGetArray (*pm_petsc_api.VecGetArray)
#define VecGetArrayRead (*pm_petsc_api.VecGetArrayRead)
#define VecGetArrayWrite (*pm_petsc_api.VecGetArrayWrite)
#define VecGhostGetLocalForm (*pm_petsc_api.VecGhostGetLocalForm)
#define VecGhostRestoreLocalForm (*pm_petsc_api.VecGhostRestoreLocalForm)
#define VecGhostUpdateBegin (*pm_petsc_api.VecGhostUpdateBegin)
#define VecGhostUpdateEnd (*pm_petsc_api.VecGhostUpdateEnd)
#define VecNorm (*pm_petsc_api.VecNorm)
#define VecPointwiseMult (*pm_petsc_api.VecPointwiseMult)
#define VecRestoreArray (*pm_petsc_api.VecRestoreArray)
#define VecRestoreArrayRead (*pm_petsc_api.VecRestoreArrayRead)
#define VecRestoreArrayWrite (*pm_petsc_api.VecRestoreArrayWrite)
#define VecWAXPY (*pm_petsc_api.VecWAXPY)

/* PETSc's own inline functions call the library by name, compiled where
 * petscmat.h is, before the names above: those the program uses are
 * redone here through the table (the same body). */
static inline PetscErrorCode pm_petsc_mat_set_value(Mat m, PetscInt i,
                                                    PetscInt j, PetscScalar v,
                                                    InsertMode mode) {
  return MatSetValues(m, 1, &i, 1, &j, &v, mode);
}
#define MatSetValue pm_petsc_mat_set_value
#endif

#endif

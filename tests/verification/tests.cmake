# Verification tests: whole runs against analytic solutions, and the
# command line's handling of bad input and numerical failure.
# Each verification program runs its own OpenMP threads on every core, so
# ctest gives it the machine (PROCESSORS 2): oversubscribed OpenMP threads
# spin against each other and run several times slower.  The scripts whose
# scenes are small run one thread (they export OMP_NUM_THREADS=1 unless the
# caller set it) and take one core (PROCESSORS 1), so ctest -j2 runs another
# test beside them.  For a machine shared with other jobs,
# tests/CMakeLists.txt also sets a short spin (GOMP_SPINCOUNT=3000) for
# every test, these included.
set(PM_VERIFY_DIR ${CMAKE_CURRENT_LIST_DIR})
file(GLOB PM_VERIFY_TESTS CONFIGURE_DEPENDS ${PM_VERIFY_DIR}/verify_*.c)
foreach(src ${PM_VERIFY_TESTS})
  get_filename_component(name ${src} NAME_WE)
  add_executable(${name} ${src})
  target_include_directories(${name} PRIVATE ${PM_TEST_SUPPORT})
  target_link_libraries(${name} PRIVATE pm_app PkgConfig::CMOCKA)
  target_compile_definitions(${name} PRIVATE PM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_test(NAME verification.${name} COMMAND ${name})
  set_tests_properties(verification.${name} PROPERTIES LABELS verification TIMEOUT 900 PROCESSORS 2)
endforeach()

add_test(NAME verification.cli
  COMMAND bash ${PM_VERIFY_DIR}/cli.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.cli PROPERTIES LABELS verification TIMEOUT 600 PROCESSORS 1)

add_test(NAME verification.cli_mpm
  COMMAND bash ${PM_VERIFY_DIR}/cli-mpm.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.cli_mpm PROPERTIES LABELS verification TIMEOUT 600 PROCESSORS 1)

add_test(NAME verification.cli_not_finite
  COMMAND bash ${PM_VERIFY_DIR}/cli-not-finite.sh $<TARGET_FILE:pointmech>)
set_tests_properties(verification.cli_not_finite PROPERTIES LABELS verification TIMEOUT 300)

add_test(NAME verification.studies
  COMMAND bash ${PM_VERIFY_DIR}/studies.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.studies PROPERTIES LABELS verification TIMEOUT 900 PROCESSORS 1)

add_test(NAME verification.restart
  COMMAND bash ${PM_VERIFY_DIR}/restart.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.restart PROPERTIES LABELS verification TIMEOUT 600 PROCESSORS 2)
# Ten interruptions (the 50-interruption soak: benchmarks/soak-resume.sh).
add_test(NAME verification.soak
  COMMAND bash ${PM_VERIFY_DIR}/soak.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR} 10 1)
set_tests_properties(verification.soak PROPERTIES LABELS verification TIMEOUT 300)
add_test(NAME verification.memory
  COMMAND bash ${PM_VERIFY_DIR}/memory.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.memory PROPERTIES LABELS verification TIMEOUT 120)

add_test(NAME verification.wait_policy
  COMMAND bash ${PM_VERIFY_DIR}/wait-policy.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.wait_policy PROPERTIES LABELS verification TIMEOUT 120)

add_test(NAME verification.membranes
  COMMAND bash ${PM_VERIFY_DIR}/membranes.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.membranes PROPERTIES LABELS verification TIMEOUT 900 PROCESSORS 2)

add_test(NAME verification.python
  COMMAND bash ${PM_VERIFY_DIR}/python.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.python PROPERTIES LABELS verification TIMEOUT 120 PROCESSORS 1)

# The scripts of tools/ that read a run's HDF5 files: through the Python
# module, each file vetted by the program first.
add_test(NAME verification.tools
  COMMAND bash ${PM_VERIFY_DIR}/tools.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.tools PROPERTIES LABELS verification TIMEOUT 120 PROCESSORS 1)

add_test(NAME verification.compare
  COMMAND bash ${PM_VERIFY_DIR}/compare.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.compare PROPERTIES LABELS verification TIMEOUT 300 PROCESSORS 1)

add_test(NAME verification.bench
  COMMAND bash ${PM_VERIFY_DIR}/bench.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.bench PROPERTIES LABELS verification TIMEOUT 450 PROCESSORS 1)

# Runs across MPI ranks (mpirun -np 2 and 3) against the same scenes on one
# process, explicit MPM (ranks.sh) and FPM (ranks-fpm.sh); ranks_migrate
# checks that migration moves particles and nothing else.
# The whole machine each (PROCESSORS 2), one at a time (RESOURCE_LOCK
# mpirun): their ranks step in lockstep, and a rank that another test's
# process takes the core from stalls the others.  Beside a one-core test
# (and the sanitizer build's tests) ranks_fpm took 316 s of wall and
# studies 296; alone, 65 and 80 (docs/validation.md, "The suite: each
# rank's status, and the ranks tests alone").  ranks_halo and ranks_output,
# a few seconds each, keep one core.
if(PM_MPI)
  add_executable(ranks_migrate ${PM_VERIFY_DIR}/ranks_migrate.c)
  target_link_libraries(ranks_migrate PRIVATE pm_app)
  add_test(NAME verification.ranks
    COMMAND bash ${PM_VERIFY_DIR}/ranks.sh $<TARGET_FILE:pointmech>
      ${PROJECT_SOURCE_DIR} $<TARGET_FILE:ranks_migrate>)
  set_tests_properties(verification.ranks PROPERTIES LABELS verification
    TIMEOUT 600 PROCESSORS 2
    RESOURCE_LOCK mpirun)
  # The neighbour exchange alone (pm_halo): random patterns on 3 ranks,
  # every operation against what each root must hold, sums in rank order.
  add_executable(ranks_halo ${PM_VERIFY_DIR}/ranks_halo.c)
  target_link_libraries(ranks_halo PRIVATE pm_app)
  add_test(NAME verification.ranks_halo
    COMMAND ${MPIEXEC_EXECUTABLE} -np 3 --bind-to none
      $<TARGET_FILE:ranks_halo>)
  set_tests_properties(verification.ranks_halo PROPERTIES LABELS verification
    TIMEOUT 60 PROCESSORS 1 RESOURCE_LOCK mpirun
    ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1;OMPI_MCA_mpi_yield_when_idle=1;OMPI_MCA_pml=ob1;OMPI_MCA_btl=self,vader")
  # The Newton layer and the implicit MPM across ranks.
  add_executable(ranks_newton ${PM_VERIFY_DIR}/ranks_newton.c)
  target_link_libraries(ranks_newton PRIVATE pm_app)
  target_include_directories(ranks_newton PRIVATE ${PM_TEST_SUPPORT})
  add_test(NAME verification.ranks_implicit
    COMMAND bash ${PM_VERIFY_DIR}/ranks-implicit.sh $<TARGET_FILE:pointmech>
      ${PROJECT_SOURCE_DIR} $<TARGET_FILE:ranks_newton>)
  set_tests_properties(verification.ranks_implicit PROPERTIES LABELS
    verification TIMEOUT 600 PROCESSORS 2
    RESOURCE_LOCK mpirun)
  # FPM's setup with no whole model on any rank (rank 0 meshes, cuts and
  # sends the parts, and lets its mesh and cells go).
  add_executable(ranks_fpm_setup ${PM_VERIFY_DIR}/ranks_fpm_setup.c)
  target_link_libraries(ranks_fpm_setup PRIVATE pm_app)
  target_include_directories(ranks_fpm_setup PRIVATE ${PM_TEST_SUPPORT})
  add_test(NAME verification.ranks_fpm
    COMMAND bash ${PM_VERIFY_DIR}/ranks-fpm.sh $<TARGET_FILE:pointmech>
      ${PROJECT_SOURCE_DIR} $<TARGET_FILE:ranks_fpm_setup>)
  set_tests_properties(verification.ranks_fpm PROPERTIES LABELS verification
    TIMEOUT 600 PROCESSORS 2
    RESOURCE_LOCK mpirun)
  # A frame across ranks written in pieces against the gathered frame.
  add_executable(ranks_output ${PM_VERIFY_DIR}/ranks_output.c)
  target_link_libraries(ranks_output PRIVATE pm_common)
  target_include_directories(ranks_output PRIVATE ${PM_TEST_SUPPORT})
  add_test(NAME verification.ranks_output
    COMMAND bash ${PM_VERIFY_DIR}/ranks-output.sh ${PROJECT_SOURCE_DIR}
      $<TARGET_FILE:ranks_output> $<TARGET_FILE:pointmech>)
  set_tests_properties(verification.ranks_output PROPERTIES LABELS
    verification TIMEOUT 300 PROCESSORS 1
    RESOURCE_LOCK mpirun)
  # Checkpoints in pieces, resumed on another count of ranks.
  add_test(NAME verification.ranks_checkpoint
    COMMAND bash ${PM_VERIFY_DIR}/ranks-checkpoint.sh $<TARGET_FILE:pointmech>
      ${PROJECT_SOURCE_DIR})
  set_tests_properties(verification.ranks_checkpoint PROPERTIES LABELS
    verification TIMEOUT 300 PROCESSORS 2
    RESOURCE_LOCK mpirun)
  # Membranes (their neighbours on other ranks) and bodies moving as
  # prescribed across ranks.
  add_test(NAME verification.ranks_membranes
    COMMAND bash ${PM_VERIFY_DIR}/ranks-membranes.sh $<TARGET_FILE:pointmech>
      ${PROJECT_SOURCE_DIR} $<TARGET_FILE:ranks_migrate>)
  set_tests_properties(verification.ranks_membranes PROPERTIES LABELS
    verification TIMEOUT 600 PROCESSORS 2
    RESOURCE_LOCK mpirun)
endif()

# Grips on regions of particles and tractions on faces (explicit MPM):
# reactions and displacements of a bar against the analytic 1-D answer.
add_test(NAME verification.mpm_grips
  COMMAND bash ${PM_VERIFY_DIR}/mpm-grips.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.mpm_grips PROPERTIES LABELS verification TIMEOUT 300)
add_test(NAME verification.mpm_contact
  COMMAND bash ${PM_VERIFY_DIR}/mpm-contact.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.mpm_contact PROPERTIES LABELS verification TIMEOUT 300)
add_test(NAME verification.implicit_stop
  COMMAND bash ${PM_VERIFY_DIR}/implicit-stop.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.implicit_stop PROPERTIES LABELS verification TIMEOUT 300 PROCESSORS 2)

add_test(NAME verification.disks
  COMMAND bash ${PM_VERIFY_DIR}/disks.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.disks PROPERTIES LABELS verification TIMEOUT 120 PROCESSORS 1 SKIP_RETURN_CODE 77)

add_test(NAME verification.static_stop
  COMMAND bash ${PM_VERIFY_DIR}/static-stop.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.static_stop PROPERTIES LABELS verification TIMEOUT 300 PROCESSORS 1)

add_test(NAME verification.kirsch
  COMMAND bash ${PM_VERIFY_DIR}/kirsch.sh $<TARGET_FILE:pointmech> ${PROJECT_SOURCE_DIR})
set_tests_properties(verification.kirsch PROPERTIES LABELS verification TIMEOUT 300 PROCESSORS 1)

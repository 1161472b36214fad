# Fluent .msh/.cas: a C test on the fixtures of tests/data/fluent (foamMeshToFluent's files and
# their binary variants: reading, the write back, hostile files), and the cross-check against
# OpenFOAM's own Fluent readers and the CLI (label foam; skipped with exit 77 only when the
# openfoam package is absent - scripts/setup.sh installs it).
cm_add_unit_test(test_fluent test_fluent.c LIBS cm_mesh_internal LABELS hostile)

// hp_sim sources are listed in sim/CMakeLists.txt; this file keeps the target non-empty until the solvers land.

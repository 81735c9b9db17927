# Sourced by the bench scripts that launch mpirun, from the repository's root: Open MPI as root and without ssh
# (a container's user), one thread per process (the ranks are the parallelism), the launch command in MPIRUN
# (oversubscribed: P = 4 on a 2-core machine, whose times are then not speeds), and v KEY FILE, the first value of
# KEY in a summary.json (mica writes one member per line).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
MPIRUN=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
v() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -n 1; }

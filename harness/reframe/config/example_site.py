# An example ReFrame configuration for a real SLURM site, to copy and adapt; nothing here is
# tested, every name is a placeholder.  Run the checks with it:
#   EFSI_REFRAME_CONFIG=my_site.py EFSI_REFRAME_SYSTEM=mycluster EFSI_BIN_DIR=/path/to/build/bin \
#     harness/reframe/run.sh batch
# and add references for it as references/mycluster.json (same layout as dev-2core.json, keys
# "mycluster:batch"), measured on an idle node of that partition.

site_configuration = {
    'systems': [
        {
            'name': 'mycluster',
            'descr': 'Example site: login nodes and one batch partition',
            # Login node names; run.sh gives --system, so this only matters without it.
            'hostnames': [r'login\d+'],
            'modules_system': 'lmod',  # or 'tmod4', or 'nomod' without environment modules
            'partitions': [
                {
                    'name': 'batch',
                    'descr': 'CPU nodes',
                    # 'slurm' asks sacct for the job's end and exit code: it needs accounting
                    # (slurmdbd).  Without it use 'squeue', as dev-2core's slurm partition.
                    'scheduler': 'slurm',
                    'launcher': 'srun',
                    # sbatch options every job gets: account, partition, QOS.
                    'access': ['--partition=batch', '--account=ACC'],
                    'environs': ['gnu-openmpi'],
                    'max_jobs': 16,
                    # srun must start the MPI library through the PMI it was built with:
                    # `srun --mpi=list` shows the site's; Open MPI 4 and 5 want pmix.
                    'env_vars': [['SLURM_MPI_TYPE', 'pmix'], ['SLURM_CPU_BIND', 'cores']],
                    # Needed for -S threads=N > 1 to ask for the cores, and for reporting.
                    'processor': {'num_cpus': 128, 'num_cpus_per_core': 1, 'num_sockets': 2,
                                  'num_cpus_per_socket': 64},
                },
            ],
        },
    ],
    'environments': [
        {
            'name': 'gnu-openmpi',
            # The modules the drivers were built with (they must also be loaded at run time).
            'modules': ['gcc/12', 'openmpi/4.1', 'fftw/3.3'],
            'cc': 'mpicc', 'cxx': 'mpicxx', 'ftn': 'mpif90',
            'target_systems': ['mycluster'],
        },
    ],
    'logging': [
        {
            'level': 'debug',
            'handlers': [
                {'type': 'stream', 'name': 'stdout', 'level': 'info', 'format': '%(message)s'},
                {'type': 'file', 'name': 'reframe.log', 'level': 'debug',
                 'format': '[%(asctime)s] %(levelname)s: %(check_info)s: %(message)s', 'append': False},
            ],
            'handlers_perflog': [
                {
                    # One line per check and run under PREFIX/perflogs/SYSTEM/PARTITION/.
                    'type': 'filelog',
                    'prefix': '%(check_system)s/%(check_partition)s',
                    'level': 'info',
                    'format': '%(check_job_completion_time)s|%(check_info)s|%(check_perfvalues)s',
                    'format_perfvars': '%(check_perf_var)s=%(check_perf_value)s %(check_perf_unit)s '
                                       '(ref %(check_perf_ref)s)|',
                    'append': True,
                },
            ],
        },
    ],
}

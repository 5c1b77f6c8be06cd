# ReFrame configuration for dev-2core, the machine EFSI-Bench is developed on: a 2-core AMD
# EPYC (Zen 4) VM with Debian 12, Open MPI 4.1.4 and SLURM 22.05.  Two partitions:
#   local  the drivers started here by mpirun, one test at a time (2 cores)
#   slurm  the one-node cluster of harness/slurm-local (its SLURM_CONF exported); jobs go
#          through sbatch and are followed with squeue, since that cluster has no accounting
#          for ReFrame's `slurm` scheduler to read through sacct
# harness/reframe/run.sh picks the system with --system, so the hostname does not matter.
# The reference values of the checks for this system are in ../references/dev-2core.json.

site_configuration = {
    'systems': [
        {
            'name': 'dev-2core',
            'descr': '2-core AMD EPYC Zen 4 VM, Debian 12 (EFSI-Bench development machine)',
            'hostnames': ['.*'],
            'partitions': [
                {
                    'name': 'local',
                    'descr': 'this machine, mpirun',
                    'scheduler': 'local',
                    'launcher': 'mpirun',
                    'environs': ['openmpi'],
                    # Two cores: two runs at once would time each other.
                    'max_jobs': 1,
                    'processor': {'num_cpus': 2, 'num_cpus_per_core': 1, 'num_sockets': 1,
                                  'num_cpus_per_socket': 2},
                    # The same binding campaign.py local asks mpirun for.
                    'env_vars': [['OMPI_MCA_hwloc_base_binding_policy', 'core']],
                },
                {
                    'name': 'slurm',
                    'descr': 'the local one-node SLURM cluster (harness/slurm-local), srun',
                    'scheduler': 'squeue',
                    'launcher': 'srun',
                    'environs': ['openmpi'],
                    'max_jobs': 2,
                    'processor': {'num_cpus': 2, 'num_cpus_per_core': 1, 'num_sockets': 1,
                                  'num_cpus_per_socket': 2},
                    # Debian's Open MPI starts under srun only through PMIx (it lacks SLURM's
                    # PMI-1/PMI-2), and MpiDefault is none; srun reads both from the
                    # environment, so the checks stay free of site options.
                    'env_vars': [['SLURM_MPI_TYPE', 'pmix'], ['SLURM_CPU_BIND', 'cores']],
                },
            ],
        },
    ],
    'environments': [
        {'name': 'openmpi', 'cc': 'mpicc', 'cxx': 'mpicxx', 'ftn': ''},
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

"""The design space at scale: energy maps, Pareto fronts and sweeps of full optimisations, for any study.

Every command takes a study of one task or a duty mix, of a crane file or a machine file, with
any registered objective; axes and columns are named by the machine's decision variables.

* :mod:`.energy_map`, :mod:`.map_values`, :mod:`.map_output`: the objective, costf2, energies and
  binding constraint over a grid of two decision variables, through the study's own NLP.
* :mod:`.pareto`: the objective against peak actuator force or rms motor torque (epsilon-constraint).
* :mod:`.spec`, :mod:`.paths`: sweep files (a base study, a grid or a Latin-hypercube sample).
* :mod:`.point`, :mod:`.runner`, :mod:`.executors`, :mod:`.table`, :mod:`.figures`: running the
  points on local processes or a Dask cluster, one Parquet table, resume, summary figures.
"""

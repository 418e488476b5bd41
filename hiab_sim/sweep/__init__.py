"""The design space at scale: energy maps over two link lengths and sweeps of full optimisations on any executor.

* :mod:`.energy_map`, :mod:`.map_output`: objective, net energy and binding constraint over a grid
  of two link lengths, vectorised over designs on the analytic path.
* :mod:`.spec`, :mod:`.paths`: sweep files (a base study, a grid or a Latin-hypercube sample).
* :mod:`.point`, :mod:`.runner`, :mod:`.executors`, :mod:`.table`, :mod:`.figures`: running the
  points on local processes or a Dask cluster, one Parquet table, resume, summary figures.
"""

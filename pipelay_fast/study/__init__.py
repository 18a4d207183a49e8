"""The study layer: sweep files and their cases (:mod:`.sweep_file`,
:mod:`.sweep`), the parallel runner (:mod:`.runner`), the Parquet results
directory (:mod:`.dataset`), the stinger choice (:mod:`.select`), the lay
table (:mod:`.laytable`) and the sweep's figure (:mod:`.plot`)."""

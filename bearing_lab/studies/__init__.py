"""Studies run on the simulator: the paper's section-5 studies and the benchmarks behind the
solver's defaults.  Each writes its page through :mod:`bearing_lab.report`.

Modules
-------
paper        -- the paper's four parametric studies and the slot's damping sensitivity
                (``run_paper_studies``; ``bearing-lab study paper``)
bench        -- speed against error, the work-precision study (``run_bench``; ``bearing-lab bench``)
bench_speed  -- speed at equal accuracy against scipy, and the default as users get it
bench_common -- what both benchmarks share: tolerances, bench scenes, measures, scipy on the same
                right-hand side

Nothing is imported here: ``import bearing_lab.studies`` costs nothing until a module is used.
"""

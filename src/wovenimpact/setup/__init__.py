"""From a case to what a run starts from: the case compiled into a Model and the State at
t = 0 (:mod:`~wovenimpact.setup.compile`), the pre-run checks (:mod:`~wovenimpact.setup.sanity`,
:mod:`~wovenimpact.setup.containment_checks`) and the spin-up of a blade
(:mod:`~wovenimpact.setup.spin_up`). Above the solver, which it runs for the first step
and the spin-up; below the run loop."""

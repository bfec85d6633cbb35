"""Analysis: what the model answers at an operating point or along a sweep.

Eigenvalues and the state-space system (:mod:`.linear_system`, :mod:`.eigen`), stability and the
stability limit (:mod:`.stability`), mode descriptions (:mod:`.modes`), root loci and the exact
continuation (:mod:`.locus`, :mod:`.continuation`), the short-circuit response (linear:
:mod:`.response`; nonlinear creep with its block stepper: :mod:`.nonlinear`,
:mod:`.block_stepper`, its inputs and rail–wheel deviations: :mod:`.nonlinear_inputs`,
:mod:`.nonlinear_irregularity`), anti-slip reaction times (:mod:`.antislip`), eigenvalue and peak
sensitivities (:mod:`.sensitivity`), the frequency response (:mod:`.frequency_response`), the
Campbell diagram with its crossings and the forced response to a torque ripple (:mod:`.campbell`)
and the system export (:mod:`.export`).  May use :mod:`model.mechanics` and :mod:`model.contact`;
never the studies or ``app``.
"""

"""Time marching with nonlinear hinges, exact between switches (:mod:`.march`): the linear
regions of the hinge laws (:mod:`.regions`), the closed-form motion and its crossings
(:mod:`.exact_motion`), smooth laws (:mod:`.smooth_laws`)."""

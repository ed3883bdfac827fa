"""Tools that check the solver from outside: the equations of motion, a fixed-step sweep, speed against error."""

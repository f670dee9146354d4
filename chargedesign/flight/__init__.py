"""The experiment that flies: a body released in free fall, and what a camera would see.

- :mod:`.release`: a start on I3 = 0 in a named chamber of the bifurcation diagram, at the
  scale the flight fits (at least five turns), and the release tolerance (how an error in the
  released omega, so I3 != 0, moves I4 over the flight; the integrator service).
- :mod:`.observation`: cameras with a sourced frame rate and marker noise; from a simulated
  track (markers on the body, noise, attitude fitted per frame, states fitted over windows)
  I4(t) is reconstructed with its uncertainty, and a control release with I3 != 0 is told
  apart from the integrable one.

docs/flight.md describes both.
"""

"""What the conditions engine accepts, and the choices it makes when a scene leaves them open."""

from __future__ import annotations

from chargedesign.limits import MAX_FIELD_DEGREE as MAX_FIELD_DEGREE  # the one cap

# the contract's field kinds, sources and realisable targets (declared in chargedesign.vocabulary)
from chargedesign.vocabulary import FIELD_KINDS as FIELD_KINDS
from chargedesign.vocabulary import REALISABLE as REALISABLE
from chargedesign.vocabulary import SOURCES as SOURCES

#: the field each source feels (its potential energy) in V
SOURCE_FIELD = {"charges": "electric", "dipoles": "magnetic", "masses": "gravity"}
#: letter of the Legendre coefficients of each field kind in messages (``fields.electric e4``)
FIELD_LETTERS = {"magnetic": "f", "electric": "e", "gravity": "g"}
#: highest accepted degree of any field (the exact derivation grows like degree^3)
#: V (lambda = rho = 0) is a quartic in gamma: spherical-harmonic degrees 0..4
V_DEGREE = 4
#: magnetic field derived when a scene gives none: a1 = 1 T and f2 = 1 T/m (a2 = 0.5 T/m)
DEFAULT_MAGNETIC = (1.0, 1.0)
#: strength of an electric term that is needed but not forced, when nothing else fixes the
#: size of the charges (V/m^k); otherwise the strength follows the body (DEFAULT_LENGTH_RULE)
DEFAULT_ELECTRIC_STRENGTH = 1.0
#: body length (m) assumed for the default strengths when none is given (``length=None``)
DEFAULT_LENGTH = 1.0
#: a default strength makes the required moments this many times smaller than the natural
#: size of the elements (measured trade-off in docs/conditions.md: no extra charge, and a
#: cancellation of at most ~300 in the degree-k moments)
DEFAULT_STRENGTH_HEADROOM = 100
#: how a default strength e_k is chosen (docs/conditions.md, "Default field strengths")
DEFAULT_LENGTH_RULE = (
    "e_k = 10^round(log10(100 |T_k| / (Q L^k))): the required degree-k moments (Racah norm "
    "|T_k| / e_k) are then about 1/100 of the natural size Q L^k of charges of total size "
    "Q = max |M_key| / L^order over the moments the other conditions fix"
)
#: a given field strength within this relative distance of a forced one is read as equal
#: (float inputs only: 0.7 and -0.28 are not exactly related in binary)
FIELD_MATCH_RTOL = 1e-9
#: which source realises each degree of V, in order of preference (others contribute nothing)
DEGREE_PREFERENCE = {
    1: ("charges", "dipoles", "masses"),
    2: ("dipoles", "charges", "masses"),
}
DEFAULT_PREFERENCE = ("charges", "dipoles", "masses")
#: the theorem's parameter symbols used by the derivation (names of chargedesign.model.case)
PARAM_NAMES = ("C", "c", "d", "n", "K", "kappa")

import math

import pytest

from chargedesign.errors import InputError
from chargedesign.params import Parameters


def test_defaults_and_contract_names():
    p = Parameters.from_mapping({"c": 0.3, "lambda": 2.0})
    assert p.C == 1.0 and p.c == 0.3 and p.lam == 2.0 and p.n == 0.0
    assert list(p.as_dict()) == ["C", "c", "d", "n", "K", "kappa", "lambda", "rho"]
    assert p.as_dict()["lambda"] == 2.0
    assert p.singular


@pytest.mark.parametrize(
    ("data", "fragment"),
    [
        ({"C": 0.0}, "parameter C: expected a number > 0"),
        ({"C": -1.0}, "parameter C: expected a number > 0"),
        ({"n": math.nan}, "parameter n: expected a finite number"),
        ({"kappa": math.inf}, "parameter kappa: expected a finite number"),
        ({"K": "1"}, "parameter K: expected a real number"),
        ({"rho": True}, "parameter rho: expected a real number"),
        ({"lambda": None}, "parameter lambda: expected a real number"),
        ({"mass": 1.0}, "parameters.mass: expected one of"),
    ],
)
def test_bad_parameters_name_the_parameter(data, fragment):
    with pytest.raises(InputError) as info:
        Parameters.from_mapping(data)
    message = str(info.value)
    assert fragment in message
    assert "\n" not in message

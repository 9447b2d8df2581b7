"""The DMU50 sphere campaign tests/check/ shares (conftest's ``sphere_campaign``,
test_check.py, test_check_fit_quality.py): layout, planted errors (um / urad by name) and the
instrument option."""

LAYOUT = "DMU50"
PLANTED = {"EX0B": 12.0, "EY0B": -8.0, "EA0B": 35.0, "EB0B": -20.0, "EX0C": 15.0,
           "EY0C": -10.0, "EA0C": 25.0, "EB0C": -40.0}
SPHERE = "sphere:u_um=0.5"

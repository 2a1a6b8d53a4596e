"""The assembly model: structure forms, parts, state layout, dotted paths, device files.

Covers :mod:`randvib.models.assembly`, its parts :mod:`randvib.models.assembly_parts`,
the structure builders :mod:`randvib.models.structure`, the device files
:mod:`randvib.models.device_file` and the shipped examples of
:mod:`randvib.datasets`. References are written out by hand here (chain and
modal matrices, the state matrix with a coil's current); every refusal class
of a device file has its own test.
"""

import numpy as np
import pytest

import randvib as rv
from randvib.datasets import device_names, device_path
from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import ElectricalDamper, Element, Spring, Transducer
from randvib.models.device_file import DeviceFileError

HOST = {"mass": [0.5, 0.05], "stiffness": [[3948.0, -197.4], [-197.4, 197.4]]}
HOST_DAMPING = [[0.62, -0.02], [-0.02, 0.02]]

SCHEMA_EXAMPLE = """
[structure]
mass = [0.5, 0.05]
stiffness = [[3948.0, -197.4], [-197.4, 197.4]]
damping = [[0.62, -0.02], [-0.02, 0.02]]
influence = [1.0, 1.0]

[[element]]
between = [1, 0]
spring = { k3 = 5e5 }

[[transducer]]
between = [1, 0]
coupling = "resistive"
c_e = 0.05
"""


def write(tmp_path, text, name="device.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_schema_example_reads_as_written(tmp_path):
    a = Assembly.from_toml(write(tmp_path, SCHEMA_EXAMPLE))
    assert a.n_dof == 2
    np.testing.assert_array_equal(a.mass, np.diag([0.5, 0.05]))
    np.testing.assert_array_equal(a.stiffness, HOST["stiffness"])
    np.testing.assert_array_equal(a.damping, HOST_DAMPING)
    (element,) = a.elements
    assert element.between == (1, 0) and element.spring.k3 == 5e5 and element.spring.k == 0
    (transducer,) = a.transducers
    assert transducer.between == (1, 0)
    assert isinstance(transducer.coupling, ElectricalDamper) and transducer.coupling.c_e == 0.05
    assert transducer.coupling.name == "resistive" and not transducer.has_load


def test_chain_matrices_by_hand():
    a = Assembly.chain(mass=[2.0, 1.0, 0.5], stiffness=[30.0, 20.0, 10.0], damping=[3, 2, 1])
    np.testing.assert_array_equal(
        a.stiffness, [[50.0, -20.0, 0.0], [-20.0, 30.0, -10.0], [0.0, -10.0, 10.0]]
    )
    np.testing.assert_array_equal(a.damping, [[5, -2, 0], [-2, 3, -1], [0, -1, 1]])
    np.testing.assert_array_equal(a.mass, np.diag([2.0, 1.0, 0.5]))
    np.testing.assert_array_equal(a.influence, [1, 1, 1])


def test_modal_host_keeps_its_modes_and_participation():
    # two modes seen at two points; the physical matrices must have the given
    # frequencies and modal damping, and r = Phi gamma
    f, zeta, m, gamma = [5.0, 12.0], [0.02, 0.05], [3.0, 1.5], [1.2, -0.4]
    phi = np.array([[1.0, 0.7], [0.4, -1.0]])
    a = Assembly.from_modes(f, zeta, m, gamma, phi, masses=[0.05])
    assert a.n_dof == 3
    host = np.ix_([0, 1], [0, 1])
    omega2 = np.sort(np.linalg.eigvals(np.linalg.solve(a.mass[host], a.stiffness[host])).real)
    np.testing.assert_allclose(np.sqrt(omega2) / (2 * np.pi), f, rtol=1e-12)
    # modal coordinates q = Phi^-1 x diagonalise M and C: Phi^T M Phi = diag(m)
    np.testing.assert_allclose(phi.T @ a.mass[host] @ phi, np.diag(m), atol=1e-12)
    expected_c = np.diag(2 * np.array(zeta) * np.array(m) * 2 * np.pi * np.array(f))
    np.testing.assert_allclose(phi.T @ a.damping[host] @ phi, expected_c, atol=1e-12)
    np.testing.assert_allclose(a.influence, [*(phi @ gamma), 1.0], rtol=1e-14)
    assert a.mass[2, 2] == 0.05 and not a.stiffness[2].any() and not a.damping[2].any()


def test_state_space_layout_with_a_coil_written_out():
    # DOF 1 (magnet) on DOF 0 (host); a coil between them with inductance, and a
    # static damper on the host against the base: X = [x0, x1, v0, v1, i]
    coil = rv.Inductive(alpha=0.2, r_load=2.0, r_coil=0.5, inductance=0.01)
    a = Assembly(
        [0.5, 0.05], HOST["stiffness"], HOST_DAMPING,
        elements=[Element((1, 0), spring=Spring(k=10.0), damping=0.03)],
        transducers=[Transducer((0, None), 0.1), Transducer((1, 0), coil)],
    )  # fmt: skip
    m = np.diag([0.5, 0.05])
    k = np.array(HOST["stiffness"]) + 10.0 * np.array([[1, -1], [-1, 1]])
    c = np.array(HOST_DAMPING) + 0.03 * np.array([[1, -1], [-1, 1]]) + np.diag([0.1, 0])
    d = np.array([-1.0, 1.0])  # u = x1 - x0
    expected = np.zeros((5, 5))
    expected[0:2, 2:4] = np.eye(2)
    expected[2:4, 0:2] = -np.linalg.solve(m, k)
    expected[2:4, 2:4] = -np.linalg.solve(m, c)
    expected[2:4, 4] = -np.linalg.solve(m, coil.alpha * d)  # force alpha i on u
    expected[4, 2:4] = coil.alpha / coil.inductance * d  # L i' = alpha u' - R i
    expected[4, 4] = -(coil.r_load + coil.r_coil) / coil.inductance
    A, B = a.linear_state_space()
    np.testing.assert_allclose(A, expected, rtol=1e-13, atol=1e-12)
    np.testing.assert_array_equal(B, [0, 0, -1, -1, 0])
    assert a.circuit_transducers == (1,)
    assert a.state_names() == ("x0", "x1", "v0", "v1", "current1")


def test_harvester_round_trip_through_the_one_dof_assembly():
    h = rv.Harvester.from_electrical(
        m=0.0226, c_m=0.049, k=57.4, alpha=0.1992, r_load=2.0, r_coil=0.48, k3=5e5,
        friction=rv.Coulomb(0.0058), stroke=0.01,
    )  # fmt: skip
    a = Assembly.from_harvester(h)
    assert a.n_dof == 1 and a.elements[0].between == (0, None)
    assert a.as_harvester().parameters() == h.parameters()
    bare = rv.preset("coulomb-td1")
    assert Assembly.from_harvester(bare).as_harvester().parameters() == bare.parameters()
    with pytest.raises(ValueError, match="not a single-mass harvester: it has 2 DOFs"):
        Assembly(**HOST, damping=HOST_DAMPING).as_harvester()


def test_dotted_paths_get_and_update():
    a = Assembly.from_toml(device_path("two_harvesters_on_host"))
    assert a.get("element.1.fc") == 0.002
    assert a.get("element.0.k3") == 5e4
    assert a.get("transducer.1.inductance") == 0.005
    b = a.updated(
        {"element.1.k3": 1e6, "transducer.0.r_load": 4.0, "structure.stiffness.0.1": -1.0}
    )
    assert b.get("element.1.k3") == 1e6 and b.get("transducer.0.r_load") == 4.0
    assert b.stiffness[0, 1] == b.stiffness[1, 0] == -1.0
    assert a.get("element.1.k3") == 5e4  # the original is unchanged
    c = Assembly(**HOST, damping=HOST_DAMPING, transducers=[Transducer((1, 0), 0.05)])
    assert c.updated({"transducer.0.c_e": 0.2}).get("transducer.0.c_e") == 0.2
    assert c.updated({"structure.mass.1": 0.1}).mass[1, 1] == 0.1
    assert set(a.parameters()) >= {"element.1.fc", "transducer.0.alpha", "structure.mass.2.2"}


@pytest.mark.parametrize(
    "path, message",
    [
        ("element.5.k3", "has 2 element"),
        ("element.0.fc", "element 0 has"),
        ("transducer.0.cee", "transducer 0 has"),
        ("structure.mass.3.0", "I, J in 0..2"),
        ("elements.0.k3", "unknown parameter path"),
    ],
)
def test_unknown_paths_are_named(path, message):
    a = Assembly.from_toml(device_path("two_harvesters_on_host"))
    with pytest.raises(ValueError, match=message):
        a.get(path)
    with pytest.raises(ValueError, match=message):
        a.updated({path: 1.0})


def test_derived_c_e_is_not_set_directly():
    a = Assembly.from_toml(device_path("two_harvesters_on_host"))
    with pytest.raises(ValueError, match="c_e follows from its circuit"):
        a.updated({"transducer.0.c_e": 0.1})


def test_strokes_on_elements_and_transducers():
    a = Assembly.from_toml(device_path("two_harvesters_on_host"))
    assert a.strokes() == [("transducer.0", (1, 0), 0.04), ("transducer.1", (2, 0), 0.04)]


def test_every_shipped_device_round_trips_through_toml(tmp_path):
    extra = Assembly(
        [[0.5, 0.01], [0.01, 0.05]], HOST["stiffness"], HOST_DAMPING, [1.0, 0.5],
        elements=[
            Element((1, None), Spring(k=-3.0, k2=2.0, k3=1e5), rv.LuGre(2.0, 0.2, 1e-3, 2e-3, 1e-2)),
            Element((0, 1), friction=rv.Tanh(0.01, 1e4), damping=0.02, stroke=0.003),
        ],
        transducers=[
            Transducer((1, 0), rv.BridgeCoil(alpha=0.2, r_coil=0.5, v_diode=0.2, battery=1.0)),
            Transducer((1, None), rv.BridgePiezo(1e-3, 1e-7, storage_capacitance=1e-5, r_load=1e4)),
            Transducer((0, None), rv.Piezo(1e-3, 1e-7, 1e5), stroke=0.002),
        ],
    )  # fmt: skip
    devices = [Assembly.from_toml(device_path(name)) for name in device_names()] + [extra]
    for a in devices:
        b = Assembly.from_toml(write(tmp_path, a.to_toml()))
        assert b.parameters() == a.parameters()
        assert [type(t.coupling) for t in b.transducers] == [
            type(t.coupling) for t in a.transducers
        ]
        assert [type(e.friction) for e in b.elements] == [type(e.friction) for e in a.elements]


def test_shipped_devices_are_found_by_name():
    assert {"host_with_harvester", "two_harvesters_on_host", "two_mass_harvester"} <= set(
        device_names()
    )
    assert device_path("host-with-harvester") == device_path("host_with_harvester")
    with pytest.raises(ValueError, match="no shipped device file 'nothing'"):
        device_path("nothing")


# ----------------------------------------------------------- refusals of a file
def refused(tmp_path, text, *fragments):
    with pytest.raises(DeviceFileError) as info:
        Assembly.from_toml(write(tmp_path, text))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"device file {tmp_path / 'device.toml'}: ")
    for fragment in fragments:
        assert fragment in message, message
    return message


def with_structure(structure: str, rest: str = "") -> str:
    return f"[structure]\n{structure}\n{rest}"


MATRICES = "mass = [0.5, 0.05]\nstiffness = [[3948.0, -197.4], [-197.4, 197.4]]\ndamping = [[0.62, -0.02], [-0.02, 0.02]]"


def test_refuses_a_singular_mass_matrix(tmp_path):
    text = with_structure(MATRICES.replace("mass = [0.5, 0.05]", "mass = [[1.0, 1.0], [1.0, 1.0]]"))
    refused(tmp_path, text, "[structure]", "`mass` must be positive definite", "singular")


def test_refuses_a_zero_mass(tmp_path):
    text = with_structure(MATRICES.replace("mass = [0.5, 0.05]", "mass = [0.5, 0.0]"))
    refused(tmp_path, text, "[structure]", "`mass`", "singular")


def test_refuses_a_non_symmetric_stiffness(tmp_path):
    text = with_structure(MATRICES.replace("[-197.4, 197.4]]", "[-190.0, 197.4]]"))
    refused(
        tmp_path, text, "[structure]", "`stiffness` must be symmetric", "(0, 1) = -197.4", "-190.0"
    )


def test_refuses_a_damping_that_feeds_energy(tmp_path):
    text = with_structure(MATRICES.replace("[0.62, -0.02]", "[-0.62, -0.02]"))
    refused(tmp_path, text, "`damping` must be positive semi-definite")


def test_refuses_a_matrix_of_the_wrong_size(tmp_path):
    text = with_structure(MATRICES.replace("[[3948.0, -197.4], [-197.4, 197.4]]", "[[3948.0]]"))
    refused(tmp_path, text, "`stiffness` is 1 x 1 but `mass` is 2 x 2")


def test_refuses_an_influence_of_the_wrong_length(tmp_path):
    refused(
        tmp_path,
        with_structure(MATRICES + "\ninfluence = [1.0]"),
        "`influence`",
        "one entry per DOF (2)",
    )


def test_refuses_an_element_on_a_dof_that_does_not_exist(tmp_path):
    text = with_structure(MATRICES, "[[element]]\nbetween = [3, 0]\nspring = { k3 = 1.0 }")
    refused(tmp_path, text, "[[element]] 0", "`between` = [3, 0] names DOF 3", "DOFs 0..1")


def test_refuses_a_transducer_on_a_dof_that_does_not_exist(tmp_path):
    text = with_structure(MATRICES, "[[transducer]]\nbetween = [1, 2]\nc_e = 0.1")
    refused(tmp_path, text, "[[transducer]] 0", "names DOF 2")


def test_refuses_a_part_joining_a_dof_to_itself(tmp_path):
    text = with_structure(MATRICES, "[[element]]\nbetween = [1, 1]\ndamping = 0.1")
    refused(tmp_path, text, "[[element]] 0", "joins DOF 1 to itself")


@pytest.mark.parametrize(
    "text, fragments",
    [
        (with_structure(MATRICES + "\nmas = 1.0"), ("[structure]", "unknown key 'mas'", "allowed")),
        (with_structure(MATRICES, "[[element]]\nbetween = [1, 0]\nsprung = { k3 = 1.0 }"),
         ("[[element]] 0", "unknown key 'sprung'")),
        (with_structure(MATRICES, "[[transducer]]\nbetween = [1, 0]\nc_e = 0.1\ncee = 1"),
         ("[[transducer]] 0", "unknown key 'cee' = 1 for coupling = 'resistive'", "c_e")),
        (with_structure(MATRICES, "[[element]]\nbetween = [1, 0]\nspring = { k4 = 1.0 }"),
         ("[[element]] 0", "`spring` has unknown key(s) 'k4'")),
        (with_structure(MATRICES, "[[elements]]\nbetween = [1, 0]"), ("unknown table or key 'elements'",)),
    ],
)  # fmt: skip
def test_refuses_unknown_keys(tmp_path, text, fragments):
    refused(tmp_path, text, *fragments)


def test_refuses_an_unknown_friction_law_and_missing_parameters(tmp_path):
    bad_law = with_structure(
        MATRICES, '[[element]]\nbetween = [1, 0]\nfriction = { law = "stick" }'
    )
    refused(tmp_path, bad_law, "`friction.law` = 'stick' is not a friction law", "coulomb")
    missing = with_structure(
        MATRICES, '[[element]]\nbetween = [1, 0]\nfriction = { law = "tanh", fc = 0.1 }'
    )
    refused(tmp_path, missing, "the tanh `friction` needs `beta`")
    negative = with_structure(
        MATRICES, '[[element]]\nbetween = [1, 0]\nfriction = { law = "coulomb", fc = -1.0 }'
    )
    refused(tmp_path, negative, "[[element]] 0", "`fc` must be >= 0", "-1.0")


def test_refuses_an_unknown_coupling_and_missing_parameters(tmp_path):
    unknown = with_structure(MATRICES, '[[transducer]]\nbetween = [1, 0]\ncoupling = "magnetic"')
    refused(tmp_path, unknown, "`coupling` = 'magnetic'", "'resistive', 'inductive', 'piezo'")
    missing = with_structure(
        MATRICES, '[[transducer]]\nbetween = [1, 0]\ncoupling = "piezo"\ntheta = 1e-3'
    )
    refused(tmp_path, missing, "needs `capacitance` for coupling = 'piezo'")
    bridge = with_structure(
        MATRICES, '[[transducer]]\nbetween = [1, 0]\ncoupling = "resistive"\nrectifier = "bridge"'
    )
    refused(tmp_path, bridge, 'with `rectifier` = "bridge"', "'inductive', 'piezo'")


def test_refuses_a_structure_given_two_ways_or_none(tmp_path):
    both = with_structure(
        MATRICES + "\nchain = { mass = [1.0], stiffness = [1.0], damping = [0.1] }"
    )
    refused(tmp_path, both, "must give the structure one way")
    refused(tmp_path, "[[element]]\nbetween = [0, 1]\n", "needs a [structure] table")


def test_refuses_modes_that_cannot_be_told_apart(tmp_path):
    text = with_structure(
        "modes = { frequency = [5.0, 9.0], damping_ratio = [0.02, 0.02], modal_mass = [1.0, 1.0], "
        "participation = [1.0, 0.5], shapes = [[1.0, 2.0], [0.5, 1.0]] }"
    )
    refused(tmp_path, text, "`shapes` must be invertible")


def test_refuses_bad_numbers_by_name(tmp_path):
    refused(
        tmp_path,
        with_structure(MATRICES.replace("[0.5, 0.05]", "[0.5, true]")),
        "`mass` must be numbers",
    )
    chain = "chain = { mass = [1.0, 1.0], stiffness = [10.0], damping = [0.1, 0.1] }"
    refused(tmp_path, with_structure(chain), "`stiffness` must have 2 entries")


def test_refuses_what_is_not_a_toml_file(tmp_path):
    refused(tmp_path, "[structure\nmass = 1", "is not valid TOML")
    with pytest.raises(DeviceFileError, match="no such file"):
        Assembly.from_toml(tmp_path / "missing.toml")
    with pytest.raises(DeviceFileError, match="is a folder"):
        Assembly.from_toml(tmp_path)


# ------------------------------------------------------------ the Python API
@pytest.mark.parametrize(
    "build, message",
    [
        (lambda: Element((1, 0)), "has no `spring`, `friction`, `damping` or `stroke`"),
        (lambda: Element((1, "ground"), damping=1.0), 'entry 1 must be an integer >= 0 or "base"'),
        (lambda: Element((1, 0), damping=-1.0), "`damping` must be >= 0"),
        (lambda: Element((1, 0), friction="coulomb"), "`friction` must be a randvib friction law"),
        (lambda: Element((1, 0), Spring(k3=float("nan"))), "`k3` must be finite"),
        (lambda: Transducer((1, 0), "coil"), "`coupling` must be a randvib coupling"),
        (lambda: Transducer((1, 0), 0.1, stroke=0.0), "`stroke` must be > 0"),
        (lambda: Assembly([1.0], [[1.0]], [[0.1]], elements=[Element((1, 0), damping=1.0)]),
         "`elements[0]`: `between` = [1, 0] names DOF 1"),
        (lambda: Assembly([1.0], [[1.0]], [[0.1]], transducers=[0.1]),
         "`transducers[0]` must be a randvib Transducer"),
        (lambda: Assembly.chain([1.0, -1.0], [1.0, 1.0], [0.0, 0.0]), "`mass` entries must be > 0"),
    ],
)  # fmt: skip
def test_python_api_refusals_name_the_argument(build, message):
    with pytest.raises(ValueError, match=None) as info:
        build()
    assert message in str(info.value)

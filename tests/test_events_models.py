"""The envelope family, events and their starts (randvib/models/event.py).

Checked against independent numbers: each envelope's square integral and
step integrals against adaptive quadrature of its value, the
Shinozuka-Sato peak against a dense grid, and the refusals' wording.
"""

import numpy as np
import pytest
from scipy import integrate

import randvib as rv
from randvib.models.event import ENVELOPES, envelope_class

ENVELOPE_CASES = [
    rv.Step(),
    rv.ShinozukaSato(2.0, 0.5, 2.0),
    rv.ShinozukaSato.unit_peak(0.05, 20.0),
    rv.Boxcar(0.5, 1.0, 0.7),
    rv.Boxcar(0.0, 1.0, 0.0),
    rv.TabulatedEnvelope([0.2, 0.5, 1.5, 2.0], [0.0, 1.0, 0.3, 0.1]),
]


def _quad(f, envelope, t):
    points = [p for p in envelope.breakpoints() if p < t]
    return integrate.quad(f, 0, t, points=points or None, epsabs=1e-15, epsrel=1e-13, limit=400)[0]


@pytest.mark.parametrize("envelope", ENVELOPE_CASES, ids=repr)
def test_square_integral_and_step_integrals_against_quadrature(envelope):
    for t in (0.3, 1.1, 2.7):
        exact = _quad(lambda s: float(envelope(s)) ** 2, envelope, t)
        assert float(envelope.square_integral(t)) == pytest.approx(exact, rel=1e-12, abs=1e-15)
    dt, n = 0.013, 207
    first, second = envelope.step_integrals(dt, n)
    edges = np.arange(n + 1) * dt
    for j in (0, 7, 38, 115, 153, n - 1):  # steps holding kinks and jumps among them
        lo, hi = edges[j], edges[j + 1]
        assert first[j] == pytest.approx(
            _quad(lambda s: float(envelope(s)), envelope, hi) - _quad(lambda s: float(envelope(s)), envelope, lo),
            abs=1e-14,
        )  # fmt: skip
        reference = _quad(lambda s: float(envelope(s)) ** 2, envelope, hi) - _quad(
            lambda s: float(envelope(s)) ** 2, envelope, lo
        )
        assert second[j] == pytest.approx(reference, abs=1e-14)
    assert second.sum() == pytest.approx(float(envelope.square_integral(n * dt)), rel=1e-12)


def test_shinozuka_sato_shape():
    env = rv.ShinozukaSato(2.0, 0.5, 2.0)
    t = np.linspace(0, 10, 200001)
    assert env.peak_time == pytest.approx(t[np.argmax(env(t))], abs=1e-4)
    assert env.peak == pytest.approx(env(t).max(), rel=1e-9)
    assert rv.ShinozukaSato.unit_peak(0.5, 2.0).peak == pytest.approx(1.0, rel=1e-14)
    assert env(0.0) == 0.0 and env(-1.0) == 0.0
    # the rise: slope A (c - b) at t = 0
    assert float(env(1e-8)) / 1e-8 == pytest.approx(2.0 * 1.5, rel=1e-6)


def test_boxcar_and_table_shapes():
    box = rv.Boxcar(0.5, 1.0, 0.25)
    np.testing.assert_allclose(box([0.0, 0.25, 0.5, 1.5, 1.625, 1.75, 3.0]),
                               [0.0, 0.5, 1.0, 1.0, 0.5, 0.0, 0.0])  # fmt: skip
    assert box.breakpoints() == (0.5, 1.5, 1.75)
    assert box.equivalent_duration(10.0) == pytest.approx(1.0 + 0.5 / 3 + 0.25 / 3)
    table = rv.TabulatedEnvelope([0.5, 1.0], [2.0, 1.0])
    np.testing.assert_allclose(table([0.4, 0.5, 0.75, 1.0, 1.1]), [0.0, 2.0, 1.5, 1.0, 0.0])
    assert table.peak == 2.0 and table.peak_time == 0.5


def test_registry_and_event():
    assert set(ENVELOPES) == {"step", "shinozuka-sato", "boxcar", "table"}
    assert envelope_class("boxcar") is rv.Boxcar
    with pytest.raises(ValueError, match="`envelope` must be one of step"):
        envelope_class("ramp")
    event = rv.Enveloped(1.5, rv.ShinozukaSato(2.0, 0.5, 2.0))
    assert event.excitation == rv.White(1.5) or event.excitation.level == 1.5
    assert event.name == "white x shinozuka-sato"
    peak = event.peak_excitation()
    assert peak.level == pytest.approx(1.5 * event.envelope.peak**2)
    assert event.parameters()["envelope"] == {"envelope": "shinozuka-sato", "a": 2.0, "b": 0.5,
                                              "c": 2.0}  # fmt: skip
    table = rv.Tabulated([0.0, 10.0, 20.0], [1.0, 2.0, 0.0])
    assert table.scaled(3.0).variance == pytest.approx(3.0 * table.variance)
    with pytest.raises(ValueError, match="not another event"):
        rv.Enveloped(event, rv.Step())
    with pytest.raises(ValueError, match="`envelope` must be a randvib envelope"):
        rv.Enveloped(rv.White(1.0), 2.0)
    with pytest.raises(ValueError, match="event is not stationary"):
        rv.as_excitation(event)


@pytest.mark.parametrize(
    "build, fragment",
    [
        (lambda: rv.ShinozukaSato(1.0, 2.0, 0.5), "`c` must be > `b` = 2.0"),
        (lambda: rv.ShinozukaSato(1.0, 1.0, 1.0), "`c` must be > `b`"),
        (lambda: rv.ShinozukaSato(-1.0, 1.0, 2.0), "`a` must be"),
        (lambda: rv.ShinozukaSato(1.0, [1.0, 2.0], 3.0), "`b` must be one number"),
        (lambda: rv.Boxcar(0.1, 0.0, 0.1), "`hold` must be"),
        (lambda: rv.Boxcar(-0.1, 1.0, 0.1), "`rise` must be"),
        (lambda: rv.TabulatedEnvelope([0.0, 2.0, 1.0], [0, 1, 0]), "strictly increasing"),
        (lambda: rv.TabulatedEnvelope([0.0, 1.0], [0, 0]), "has no event"),
        (lambda: rv.TabulatedEnvelope([0.0, 1.0], [0, -1]), "`envelope` must be"),
        (lambda: rv.TabulatedEnvelope([-1.0, 1.0], [1, 1]), "`time` must be"),
        (lambda: rv.TabulatedEnvelope([0.0], [1.0]), "length >= 2"),
    ],
)
def test_bad_envelopes_are_refused_by_name(build, fragment):
    with pytest.raises(ValueError, match=fragment.replace("(", r"\(").replace("[", r"\[")):
        build()


def test_table_from_csv(tmp_path):
    path = tmp_path / "event.csv"
    path.write_text("time,envelope\n0,0\n1,1\n3,0\n")
    table = rv.TabulatedEnvelope.from_csv(path)
    assert table.parameters() == {"envelope": "table", "t_first": 0.0, "t_last": 3.0,
                                  "peak": 1.0, "rows": 3}  # fmt: skip
    (tmp_path / "bad.csv").write_text("t,e\n0,1\n")
    with pytest.raises(ValueError, match="must have the columns time, envelope"):
        rv.TabulatedEnvelope.from_csv(tmp_path / "bad.csv")


def test_event_start():
    mono = rv.preset("figure9")
    bistable = rv.Harvester(m=0.0226, c_m=0.05, c_e=0.05, k=-57.4, k3=5e5)
    assert rv.EventStart.of("rest", bistable) == rv.EventStart("rest")
    well = rv.EventStart.of("unexcited", bistable)
    assert well.z == pytest.approx(np.sqrt(57.4 / 5e5)) and well.v == 0.0
    assert rv.EventStart.of("unexcited", mono).is_zero
    free = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.0, k=0.0)
    assert rv.EventStart.of("unexcited", free).is_zero
    given = rv.EventStart.of((1e-3, -0.1), mono)
    assert (given.kind, given.z, given.v) == ("state", 1e-3, -0.1)
    assert "unexcited (z = 0.01071 m" in well.describe()
    with pytest.raises(ValueError, match="`start` must be one of 'rest', 'unexcited'"):
        rv.EventStart.of("stationary", mono)
    with pytest.raises(ValueError, match="`start` state must be finite"):
        rv.EventStart.of((np.nan, 0.0), mono)

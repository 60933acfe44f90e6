"""Railway scenes for ``mbsuite run`` (entry point ``mbsuite.scenes: railway``).

The contact-mechanics scenes are example scripts under ``examples/railway/``
(:func:`core.scenes.example_scene`): ``mbsuite run NAME`` runs the very file a user reads and
copies.

* ``railway-contact-geometry`` (``contact_geometry.py``) -- rigid contact geometry of new S1002
  wheels on UIC60 rails inclined 1:40 (gauge 1435 mm, flange-back spacing 1360 mm,
  r0 = 460 mm): Delta r and contact angles against lateral shift, flange-contact onset,
  equivalent conicity (EN 15302) at 2, 3 and 4 mm; the script to adapt for one's own profiles;
* ``railway-creep-curves`` (``creep_curves.py``) -- creep curves of every creep law for one
  representative contact (N = 100 kN, a = 6 mm, b = 4 mm, mu = 0.3, G = 80 GPa, nu = 0.28):
  Fx(xi), Fy(eta) and the spin effect Fy(phi);
* ``railway-two-point-contact`` (``two_point_contact.py``) -- two-point (tread + flange) contact
  of a conical wheel with a tight flange root on UIC60 1:40, with and without yaw (flange lead),
  checked by a brute-force gap scan; the quasi-static elastic case under a wheel load;
* ``railway-manchester-contact`` (``manchester_contact.py``) -- the Manchester contact benchmark,
  Case A-2.2, as defined in CONTACT's example: our quasi-static rolling solution (Hertz +
  FASTSIM, Polach 2000, Kalker linear, creep forces in the vertical balance) side by side with
  CONTACT's reference results.

The vehicle scenes follow from :func:`railway.vehicle_scenes.vehicle_scenes`.

Units of the written tables: the railway command line's (``mbsuite railway ...``) -- lengths in mm,
contact angles in deg, wheelset yaw and roll in mrad, forces in kN, moments in kN m, moduli in GPa,
creepages [-] and spin [1/m] -- in every table of a scene, so one quantity never appears in two
units (:func:`railway.tables.display_units` converts the SI tables of the library functions).
"""

from __future__ import annotations

__all__ = ["railway_scenes"]


def railway_scenes():
    """The railway scenes (entry point ``mbsuite.scenes: railway``)."""
    from core.scenes import example_scene

    from .vehicle_scenes import vehicle_scenes

    return [
        example_scene("railway-contact-geometry", "railway/contact_geometry.py",
                      "Wheel-rail contact geometry: S1002 / UIC60 1:40, delta r, contact angles, conicity",
                      "Rigid contact-geometry table of new S1002 wheels on UIC60 rails inclined 1:40 "
                      "(gauge 1435, flange-back 1360, r0 460 mm) and the equivalent conicity after EN 15302."),
        example_scene("railway-creep-curves", "railway/creep_curves.py",
                      "Creep curves of all creep laws (Kalker linear, SHE, Polach 2000/2005, FASTSIM)",
                      "Fx(xi), Fy(eta) and the spin effect at N = 100 kN, a = 6 mm, b = 4 mm, mu = 0.3, "
                      "G = 80 GPa, nu = 0.28."),
        example_scene("railway-two-point-contact", "railway/two_point_contact.py",
                      "Two-point (tread + flange) wheel-rail contact and flange lead under yaw",
                      "Conical 1:40 wheel with a tight flange root on UIC60 1:40: rigid two-point onset "
                      "with and without yaw, brute-force gap check, quasi-static elastic case."),
        example_scene("railway-manchester-contact", "railway/manchester_contact.py",
                      "Manchester contact benchmark, Case A-2.2, against CONTACT's reference results",
                      "S1002 / UIC60 1:40, 10 kN per wheel, V = 2 m/s, mu = 0.3, y = 0..10 mm with yaw "
                      "2.4 mrad/mm (Shackleton & Iwnicki 2008, VSD 46:91-120, as in CONTACT's example): "
                      "quasi-static rolling with FASTSIM, Polach 2000 and Kalker linear vs CONTACT rev. 2447."),
    ] + vehicle_scenes()

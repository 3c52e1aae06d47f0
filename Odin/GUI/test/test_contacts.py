"""gui.core.contacts: a run's contacts told apart, support from those the run made."""
from gui.core.contacts import ContactLedger


def test_resting_contacts_are_support_and_new_or_deeper_ones_are_made_by_the_run():
    ledger = ContactLedger([("table", "can", 0.0002), ("cart/base", "ground", 0.0001)])
    ledger.see("can", "table", 0.0003, 0.5)                       # rests, either order
    ledger.see("arm/hand", "can", 0.004, 1.25)                    # the path touched the can
    ledger.see("arm/hand", "can", 0.006, 1.5)
    ledger.see("ground", "cart/base", 0.03, 2.0)    # sunk in soft contacts: still its floor
    ledger.see("crane/boom", "crane_2/boom", 0.02, 2.5)
    assert ledger.support == [dict(first="can", second="table", depth_m=0.0003),
                              dict(first="cart/base", second="ground", depth_m=0.03)]
    assert ledger.made == [
        dict(first="arm/hand", second="can", first_time_s=1.25, depth_m=0.006),
        dict(first="crane/boom", second="crane_2/boom", first_time_s=2.5, depth_m=0.02)]
    assert ledger.describe() == (
        "2 colliding pairs made by the path (crane/boom | crane_2/boom 20.0 mm at 2.50 s, "
        "arm/hand | can 6.0 mm at 1.25 s), 2 resting contacts")


def test_a_quiet_run_says_so():
    assert ContactLedger([]).describe() == "0 colliding pairs made by the path, 0 resting contacts"

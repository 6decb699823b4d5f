from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.tf import Buffer, MessageFilter, make_transform_stamped


class _TF:
    def __init__(self, transforms):
        self.transforms = transforms


def _odom_at(buf, t):
    tf = make_transform_stamped("odom", "base", Time.from_sec(t), (0, 0, 0), (0, 0, 0, 1))
    buf.add_message(_TF([tf]))


def test_a_message_waits_for_tf_then_goes_through_in_order():
    buf = Buffer()
    _odom_at(buf, 0.05)
    done = []

    def process(stamp):
        if not buf.can_transform("odom", "base", stamp):
            return False
        done.append(stamp)
        return True

    f = MessageFilter(buf, process, queue_size=2)
    f.add(0.1)
    f.add(0.2)
    f.add(0.3)  # the queue keeps the newest two
    assert len(f) == 2 and done == []
    _odom_at(buf, 0.25)  # answers for 0.2 only: 0.3 waits on
    assert done == [0.2] and len(f) == 1
    _odom_at(buf, 0.35)
    assert done == [0.2, 0.3] and len(f) == 0

"""pcl_msgs/PolygonMesh messages for the Python rostests (imported from their folder)."""
import struct

from pcl_msgs.msg import PolygonMesh, Vertices
from sensor_msgs.msg import PointCloud2, PointField


def mesh_msg(vertices, polygons, frame):
    """A PolygonMesh: vertices (x, y, z) as float32 in a PointCloud2, polygons as index lists."""
    cloud = PointCloud2()
    cloud.header.frame_id = frame
    cloud.height, cloud.width = 1, len(vertices)
    cloud.fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
                    for i, n in enumerate("xyz")]
    cloud.point_step, cloud.row_step = 12, 12 * len(vertices)
    cloud.data = b"".join(struct.pack("<3f", *v) for v in vertices)
    cloud.is_dense = True
    msg = PolygonMesh()
    msg.header.frame_id = frame
    msg.cloud = cloud
    msg.polygons = [Vertices(vertices=list(p)) for p in polygons]
    return msg

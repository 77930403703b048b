// SPDX-License-Identifier: BSD-3-Clause
// The points of an object_cloud_t, unpacked: the message carries them packed
// (int16 positions about an origin, 8-bit normals and confidence, deflated by
// zlib; layout in object_cloud_t.lcm). A Java planner copies this class.
import graspfill.object_cloud_t;
import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.zip.DataFormatException;
import java.util.zip.Inflater;

public final class ObjectCloudPoints {
  /** x0 y0 z0 x1 ... in the gripper frame G [m]. */
  public final float[] xyz;
  /** Unit normals, 3 per point, or none (length 0). */
  public final float[] normals;
  /** object_cloud_t.OBSERVED, SURFACE or SYMMETRY per point. */
  public final byte[] provenance;
  /** Trust in each point, 0..1. */
  public final float[] confidence;

  private ObjectCloudPoints(int n, boolean hasNormals) {
    xyz = new float[3 * n];
    normals = new float[hasNormals ? 3 * n : 0];
    provenance = new byte[n];
    confidence = new float[n];
  }

  /** Unpacks the cloud's points; IOException if the packed bytes are not what the header says. */
  public static ObjectCloudPoints unpack(object_cloud_t cloud) throws IOException {
    int n = cloud.num_points;
    boolean hasNormals = cloud.has_normals != 0;
    int size = n * (6 + (hasNormals ? 3 : 0) + 2);
    byte[] raw = new byte[size];
    Inflater inflater = new Inflater();
    try {
      inflater.setInput(cloud.packed_points);
      int got = inflater.inflate(raw);
      if (got != size || !inflater.finished()) {
        throw new IOException("object_cloud_t: the points do not inflate to " + size + " bytes");
      }
    } catch (DataFormatException e) {
      throw new IOException("object_cloud_t: the packed points are not a zlib stream", e);
    } finally {
      inflater.end();
    }
    ObjectCloudPoints points = new ObjectCloudPoints(n, hasNormals);
    ByteBuffer in = ByteBuffer.wrap(raw).order(ByteOrder.LITTLE_ENDIAN);
    for (int k = 0; k < 3; ++k) {
      for (int i = 0; i < n; ++i) {
        points.xyz[3 * i + k] = (float) (cloud.origin[k] + cloud.step_m * in.getShort());
      }
    }
    for (int k = 0; hasNormals && k < 3; ++k) {
      for (int i = 0; i < n; ++i) points.normals[3 * i + k] = in.get() / 127.0f;
    }
    in.get(points.provenance);
    for (int i = 0; i < n; ++i) points.confidence[i] = (in.get() & 0xff) / 255.0f;
    return points;
  }
}

// SPDX-License-Identifier: BSD-3-Clause
// Joins the messages of graspfill's cloud channel back into whole
// object_cloud_t: on LCM's UDP multicast each cloud comes as one-datagram
// slices (object_cloud_chunk_t.lcm); a log's whole object_cloud_t passes
// through. One cloud at a time: a slice of another cloud drops an
// unfinished one. A Java planner copies this class (java.util.zip only).
import graspfill.object_cloud_chunk_t;
import graspfill.object_cloud_t;
import java.io.IOException;
import java.nio.ByteBuffer;
import java.util.zip.CRC32;

public final class ObjectCloudAssembler {
  private long utime, seq;
  private int numBytes, crc32, numChunks;
  private boolean pending = false;
  private boolean[] have;
  private int missing;
  private byte[] cloud;
  private boolean completed = false;
  private long doneUtime, doneSeq;
  private int doneNumBytes, doneCrc32, doneNumChunks;
  /** Unfinished clouds dropped because a slice of another one came. */
  public long droppedUnfinished = 0;

  /**
   * Takes one message's payload; gives the whole cloud once its last slice
   * came (or at once for a whole object_cloud_t), else null (slices still
   * missing, or a repeat). IOException for another type or a bad slice.
   */
  public object_cloud_t add(byte[] data) throws IOException {
    if (data.length >= 8 && ByteBuffer.wrap(data).getLong() == object_cloud_t.LCM_FINGERPRINT) {
      if (pending) ++droppedUnfinished;
      pending = false;
      return new object_cloud_t(data);
    }
    object_cloud_chunk_t c = new object_cloud_chunk_t(data);
    if (c.cloud_num_bytes <= 0 || c.num_chunks <= 0 || c.num_chunks > c.cloud_num_bytes) {
      throw new IOException("object_cloud_chunk_t: a cloud of " + c.cloud_num_bytes + " bytes in "
          + c.num_chunks + " slices");
    }
    int slice = (int) (((long) c.cloud_num_bytes + c.num_chunks - 1) / c.num_chunks);
    long offset = (long) c.chunk_index * slice;
    if (c.chunk_index < 0 || c.chunk_index >= c.num_chunks || c.offset != offset
        || c.num_bytes != Math.min(slice, c.cloud_num_bytes - offset)) {
      throw new IOException("object_cloud_chunk_t: slice " + c.chunk_index + " does not fit");
    }
    if (completed && c.utime == doneUtime && c.seq == doneSeq && c.cloud_num_bytes == doneNumBytes
        && c.cloud_crc32 == doneCrc32 && c.num_chunks == doneNumChunks) {
      return null;  // a repeat of the cloud just given
    }
    if (!pending || c.utime != utime || c.seq != seq || c.cloud_num_bytes != numBytes
        || c.cloud_crc32 != crc32 || c.num_chunks != numChunks) {
      if (pending) ++droppedUnfinished;
      pending = true;
      utime = c.utime;
      seq = c.seq;
      numBytes = c.cloud_num_bytes;
      crc32 = c.cloud_crc32;
      numChunks = c.num_chunks;
      have = new boolean[numChunks];
      missing = numChunks;
      cloud = new byte[numBytes];
    }
    if (have[c.chunk_index]) return null;
    have[c.chunk_index] = true;
    System.arraycopy(c.data, 0, cloud, c.offset, c.num_bytes);
    if (--missing > 0) return null;
    pending = false;
    CRC32 check = new CRC32();
    check.update(cloud);
    if ((int) check.getValue() != crc32) {
      throw new IOException("object_cloud_chunk_t: the joined cloud's CRC-32 differs");
    }
    completed = true;
    doneUtime = utime;
    doneSeq = seq;
    doneNumBytes = numBytes;
    doneCrc32 = crc32;
    doneNumChunks = numChunks;
    byte[] whole = cloud;
    cloud = null;
    return new object_cloud_t(whole);
  }
}

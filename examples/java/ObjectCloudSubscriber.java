// SPDX-License-Identifier: BSD-3-Clause
// A planner's side of graspfill, in Java: subscribes to the object clouds and
// prints a summary of each. Needs LCM's jar (liblcm-java),
// graspfill_lcmtypes.jar (classes graspfill.<type>, built by graspfill),
// ObjectCloudAssembler (beside this file), which joins the one-datagram
// slices each cloud comes in on UDP multicast, and ObjectCloudPoints, which
// unpacks the points. LCM's reader thread only queues the messages
// (MessageAggregator); they are joined and decoded on the main thread, so
// that the reader empties the socket while a cloud is being decoded.
//
// usage: java -cp lcm.jar:graspfill_lcmtypes.jar:. ObjectCloudSubscriber
//            [URL] [--channel NAME] [--count N] [--timeout-s S]
//   URL   LCM's URL (default: LCM_DEFAULT_URL, else UDP multicast); a bus log
//         plays as "file://LOG?speed=0" (at its end LCM's Java file provider
//         prints an EOFException on stderr: harmless)
// Prints per cloud, as the C++ example does:
//   seq=S utime=U grasp=G final=F points=N observed=A surface=B symmetry=C holes=H unobserved=U trusted=T
//   (T: the added points the repair stands behind, confidence above 0.5)
// Exit: 0 once N clouds (default 1) are received; 1 on a usage error, an
// undecodable message or S seconds (default 10) without a cloud before that.
import graspfill.hole_t;
import graspfill.object_cloud_t;
import java.io.IOException;
import lcm.lcm.LCM;
import lcm.lcm.MessageAggregator;

public class ObjectCloudSubscriber {
  private static void print(object_cloud_t cloud) throws IOException {
    ObjectCloudPoints points = ObjectCloudPoints.unpack(cloud);
    long[] byProvenance = new long[3];
    for (byte p : points.provenance) {
      if (p >= 0 && p < 3) ++byProvenance[p];
    }
    // Holes whose inside nothing is known of (an open mouth): keep clear.
    int unobserved = 0;
    for (hole_t h : cloud.holes) {
      if (h.unobserved != 0) ++unobserved;
    }
    // Added points more likely right than not; the rest of the added ones
    // (a lid no view saw) are a guess, which the safe bound covers.
    long trusted = 0;
    for (int i = 0; i < points.provenance.length; ++i) {
      if (points.provenance[i] != object_cloud_t.OBSERVED && points.confidence[i] > 0.5f) {
        ++trusted;
      }
    }
    System.out.printf("seq=%d utime=%d grasp=%d final=%d points=%d observed=%d surface=%d "
            + "symmetry=%d holes=%d unobserved=%d trusted=%d%n", cloud.seq, cloud.utime, cloud.grasp_id,
        cloud.is_final, cloud.num_points, byProvenance[object_cloud_t.OBSERVED],
        byProvenance[object_cloud_t.SURFACE], byProvenance[object_cloud_t.SYMMETRY],
        cloud.num_holes, unobserved, trusted);
    System.out.flush();
  }

  private static int usage() {
    System.err.println("usage: ObjectCloudSubscriber [URL] [--channel NAME] [--count N] "
        + "[--timeout-s S]");
    return 1;
  }

  private static int run(String[] args) throws IOException {
    String url = null;
    String channel = "GRASPFILL_OBJECT_CLOUD";
    int count = 1;
    int timeoutS = 10;
    for (int i = 0; i < args.length; ++i) {
      boolean hasValue = i + 1 < args.length;
      if (args[i].equals("--channel") && hasValue) channel = args[++i];
      else if (args[i].equals("--count") && hasValue) count = Integer.parseInt(args[++i]);
      else if (args[i].equals("--timeout-s") && hasValue) timeoutS = Integer.parseInt(args[++i]);
      else if (url == null && !args[i].startsWith("-")) url = args[i];
      else return usage();
    }
    if (count < 1 || timeoutS < 1) return usage();
    LCM lcm = url == null ? new LCM() : new LCM(url);
    MessageAggregator queue = new MessageAggregator();
    lcm.subscribe(channel, queue);
    ObjectCloudAssembler slices = new ObjectCloudAssembler();
    try {
      int received = 0;
      // The timeout counts from the latest cloud.
      long deadline = System.nanoTime() + timeoutS * 1_000_000_000L;
      while (received < count) {
        long leftMs = (deadline - System.nanoTime()) / 1_000_000L;
        MessageAggregator.Message message = leftMs > 0 ? queue.getNextMessage(leftMs) : null;
        if (message == null) {
          System.err.printf("ObjectCloudSubscriber: no cloud on %s for %d s%n", channel, timeoutS);
          return 1;
        }
        object_cloud_t cloud;
        try {
          cloud = slices.add(message.data);
          if (cloud == null) continue;  // more slices to come
          print(cloud);
        } catch (IOException e) {
          System.err.println("ObjectCloudSubscriber: undecodable message on " + channel + ": " + e);
          return 1;
        }
        ++received;
        deadline = System.nanoTime() + timeoutS * 1_000_000_000L;
      }
      return 0;
    } finally {
      lcm.close();
    }
  }

  public static void main(String[] args) throws IOException {
    int code;
    try {
      code = run(args);
    } catch (NumberFormatException e) {
      code = usage();
    }
    System.exit(code);
  }
}

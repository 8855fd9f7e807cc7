/* A C program using the detector through tethash.h, checked against a result worked out by hand:
 *   tet 0 (object 0): the unit corner tet (0,0,0) (1,0,0) (0,1,0) (0,0,1);
 *   tet 1 (object 1): base (0,0,-1) (1,0,-1) (0,1,-1) below it, apex vertex 7 at (0.2, 0.2, 0.1).
 * Vertex 7 lies in tet 0 with barycentric coordinates (0.5, 0.2, 0.2, 0.1); nothing else touches. Every edge from
 * vertex 7 leaves tet 0 through its face z = 0 (outward normal -z), 0.1 below the vertex, so the penetration depth
 * is 0.1 and the direction (0, 0, -1). Moving vertex 7 to z = -0.1 in the caller's array (no new registration)
 * leaves no contact. The edges from the base to vertex 7 (4-7, 5-7, 6-7) cross tet 0's face z = 0 at t = 1 / 1.1 of
 * the way, their inner end (vertex 7) above it, the triangle's normal (0, 0, -1): three edge-face contacts, none
 * after the move. Moving vertex 7 back up over a step, continuous detection finds it passing through tet 0's base at
 * t = 0.5. Exit status 0 when everything holds, 1 otherwise. */
#include <tethash/tethash.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static int failures = 0;

static void check(int ok, const char* what)
{
    if (!ok) {
        fprintf(stderr, "FAILED: %s\n", what);
        ++failures;
    }
}

static int near(double a, double b)
{
    return fabs(a - b) <= 1e-12;
}

int main(void)
{
    double xyz[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 1, 0, -1, 0, 1, -1, 0.2, 0.2, 0.1};
    const int32_t tets[2 * 4] = {0, 1, 2, 3, 4, 5, 6, 7};
    const int32_t vertex_object[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    const int32_t tet_object[2] = {0, 1};

    tethash_detector* d = NULL;
    if (tethash_detector_create(&d) != TETHASH_OK) {
        fprintf(stderr, "create: %s\n", tethash_last_error());
        return 1;
    }
    check(tethash_detector_set_threads(d, 1) == TETHASH_OK, "set_threads");
    if (tethash_detector_set_topology(d, tets, 2, 8, vertex_object, tet_object) != TETHASH_OK) {
        fprintf(stderr, "set_topology: %s\n", tethash_last_error());
        tethash_detector_destroy(d);
        return 1;
    }

    int64_t count = -1;
    check(tethash_detector_detect(d, xyz, 8, &count) == TETHASH_OK, "detect");
    check(count == 1, "one contact");
    check(tethash_detector_compute_penetration(d, xyz, 8) == TETHASH_OK, "compute_penetration");
    tethash_contact c;
    memset(&c, 0, sizeof c);
    check(tethash_detector_contact(d, 0, &c) == TETHASH_OK, "contact 0");
    printf("contact vertex %d tet %d bary %.3f %.3f %.3f %.3f depth %.6f direction %.3f %.3f %.3f\n", c.vertex, c.tet,
           c.bary[0], c.bary[1], c.bary[2], c.bary[3], c.depth, c.direction[0], c.direction[1], c.direction[2]);
    check(c.vertex == 7 && c.tet == 0, "vertex 7 in tet 0");
    check(c.vertex_object == 1 && c.tet_object == 0, "objects 1 in 0");
    check(near(c.bary[0], 0.5) && near(c.bary[1], 0.2) && near(c.bary[2], 0.2) && near(c.bary[3], 0.1), "bary");
    check(near(c.depth, 0.1), "depth 0.1");
    check(near(c.direction[0], 0) && near(c.direction[1], 0) && near(c.direction[2], -1), "direction -z");

    /* The arrays form. */
    int32_t vertex[1] = {-1}, tet[1] = {-1};
    double depth[1] = {0};
    check(tethash_detector_get_contacts(d, 1, vertex, tet, NULL, depth, NULL) == TETHASH_OK, "get_contacts");
    check(vertex[0] == 7 && tet[0] == 0 && near(depth[0], 0.1), "arrays agree");

    tethash_stats stats;
    check(tethash_detector_stats(d, &stats) == TETHASH_OK, "stats");
    check(stats.contacts == 1 && stats.threads == 1 && stats.cell_size > 0, "stats of the detection");

    /* A wrong size is an error with a message, not a crash. */
    check(tethash_detector_detect(d, xyz, 7, &count) == TETHASH_ERROR_INVALID_ARGUMENT, "wrong size refused");
    check(strstr(tethash_last_error(), "num_vertices") != NULL, "message names num_vertices");
    printf("expected error: %s\n", tethash_last_error());

    /* Edge-face contacts: the three edges into tet 0 through its base. */
    check(tethash_detector_find_edge_contacts(d, xyz, 8, &count) == TETHASH_OK, "find_edge_contacts");
    check(count == 3, "three edge-face contacts");
    if (count == 3) {
        int32_t edge[6], face[9], objects[6], inner[3];
        double t[3], normal[9];
        check(tethash_detector_get_edge_contacts(d, 3, edge, face, objects, t, NULL, inner, normal) == TETHASH_OK,
              "get_edge_contacts");
        for (int i = 0; i < 3; ++i) {
            check(edge[2 * i] == 4 + i && edge[2 * i + 1] == 7, "edges 4-7, 5-7, 6-7");
            check(face[3 * i] + face[3 * i + 1] + face[3 * i + 2] == 3 && face[3 * i] <= 2 && face[3 * i + 1] <= 2,
                  "face 0 1 2");
            check(objects[2 * i] == 1 && objects[2 * i + 1] == 0, "edge of object 1 through a face of object 0");
            check(near(t[i], 1 / 1.1) && inner[i] == 1, "crossing 1 / 1.1 along, vertex 7 inside");
            check(near(normal[3 * i], 0) && near(normal[3 * i + 1], 0) && near(normal[3 * i + 2], -1), "normal -z");
        }
        printf("edge-face contact: edge %d %d, t %.6f, normal %.3f %.3f %.3f\n", edge[0], edge[1], t[0], normal[0],
               normal[1], normal[2]);
    }
    check(tethash_detector_get_edge_contacts(d, 2, NULL, NULL, NULL, NULL, NULL, NULL, NULL) ==
              TETHASH_ERROR_INVALID_ARGUMENT,
          "capacity below the count refused");

    /* The caller moves its own array; the next detection reads it in place. */
    xyz[7 * 3 + 2] = -0.1;
    check(tethash_detector_detect(d, xyz, 8, &count) == TETHASH_OK, "detect after the move");
    check(count == 0, "no contact after the move");
    check(tethash_detector_find_edge_contacts(d, xyz, 8, &count) == TETHASH_OK && count == 0,
          "no edge-face contact after the move");

    /* Continuous detection over a step: vertex 7 back from z = -0.1 to 0.1 passes through tet 0's base face (0 1 2)
     * at t = 0.5; its edges cross that face inside it, meeting no edge: one vertex-face contact. */
    {
        double back[8 * 3];
        memcpy(back, xyz, sizeof back);
        back[7 * 3 + 2] = 0.1;
        check(tethash_detector_detect_continuous(d, xyz, back, 8, 1e-6, 1000000, &count) == TETHASH_OK,
              "detect_continuous");
        check(count == 1, "one continuous contact");
        int32_t kind = -1, ids[4] = {-1, -1, -1, -1};
        double toi = -1;
        if (count == 1) {
            check(tethash_detector_get_continuous_contacts(d, 1, &kind, ids, &toi) == TETHASH_OK,
                  "get_continuous_contacts");
            check(kind == 0 && ids[0] == 7, "vertex 7 against a face");
            check(ids[1] + ids[2] + ids[3] == 3 && ids[1] * ids[2] * ids[3] == 0 && ids[1] != ids[2] &&
                      ids[1] != ids[3] && ids[2] != ids[3],
                  "the face 0 1 2");
            check(toi <= 0.5 && toi > 0.4999, "at t = 0.5");
        }
        check(tethash_detector_detect_continuous(d, xyz, xyz, 8, 1e-6, 1000000, &count) == TETHASH_OK && count == 0,
              "no continuous contact without motion");
    }

    /* The locality rule: vertex 7 lies 0.3 from vertex 0, a corner of the face 0 1 2 it passes through, at rest (the
     * first positions). In one group with a reach of 0.5 the pair is local and left out, though the grid met it;
     * with a reach of 0.05, or in two groups (by object), it is far and found again. */
    {
        const double rest[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 1, 0, -1, 0, 1, -1, 0.2, 0.2, 0.1};
        const int32_t one_group[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        double back[8 * 3];
        memcpy(back, xyz, sizeof back);
        back[7 * 3 + 2] = 0.1;
        const double wide = 0.25, narrow = 0.0025;
        int64_t pairs = -1;
        check(tethash_detector_set_continuous_locality(d, rest, 8, one_group, &wide, 1) == TETHASH_OK,
              "set_continuous_locality");
        check(tethash_detector_detect_continuous(d, xyz, back, 8, 1e-6, 1000000, &count) == TETHASH_OK && count == 0,
              "a local pair is left out");
        check(tethash_detector_continuous_broad_phase_pairs(d, &pairs) == TETHASH_OK && pairs >= 1,
              "the grid met the local pair");
        check(tethash_detector_set_continuous_locality(d, rest, 8, one_group, &narrow, 1) == TETHASH_OK &&
                  tethash_detector_detect_continuous(d, xyz, back, 8, 1e-6, 1000000, &count) == TETHASH_OK &&
                  count == 1,
              "a far pair is found");
        const double reaches[2] = {wide, wide};
        check(tethash_detector_set_continuous_locality(d, rest, 8, vertex_object, reaches, 2) == TETHASH_OK &&
                  tethash_detector_detect_continuous(d, xyz, back, 8, 1e-6, 1000000, &count) == TETHASH_OK &&
                  count == 1,
              "a pair of two groups is never local");
        /* Bad input names what is wrong; the rule before stays. */
        check(tethash_detector_set_continuous_locality(d, rest, 8, vertex_object, &wide, 1) ==
                  TETHASH_ERROR_INVALID_ARGUMENT,
              "a group outside [0, num_groups) refused");
        check(strstr(tethash_last_error(), "vertex 4 is in group 1") != NULL, "message names the vertex and group");
        check(tethash_detector_set_continuous_locality(d, rest, 7, one_group, &wide, 1) ==
                  TETHASH_ERROR_INVALID_ARGUMENT,
              "a vertex count other than the topology's refused");
        check(strstr(tethash_last_error(), "num_vertices is 7") != NULL, "message names num_vertices");
        check(tethash_detector_set_continuous_locality(d, rest, 8, one_group, NULL, 1) == TETHASH_ERROR_NULL_ARGUMENT,
              "NULL reach_sq refused");
        check(strstr(tethash_last_error(), "reach_sq") != NULL, "message names reach_sq");
        check(tethash_detector_detect_continuous(d, xyz, back, 8, 1e-6, 1000000, &count) == TETHASH_OK && count == 1,
              "the rule before stays");
        check(tethash_detector_set_continuous_locality(d, rest, 8, NULL, NULL, 0) == TETHASH_OK &&
                  tethash_detector_detect_continuous(d, xyz, back, 8, 1e-6, 1000000, &count) == TETHASH_OK &&
                  count == 1,
              "no rule");
    }

    tethash_detector_destroy(d);

    /* Continuous queries: the vertex from (0.2, 0.2, 1) to (0.2, 0.2, -1) through the still triangle (0,0,0),
     * (1,0,0), (0,1,0) meets it at t = 0.5; two edges, (0,0,0)-(1,0,0) still and (0.5,-1,1)-(0.5,1,1) moving down by 2,
     * cross at t = 0.5; raised by 3, they never meet. */
    {
        double start[12] = {0.2, 0.2, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
        double end[12] = {0.2, 0.2, -1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
        double ea[12] = {0, 0, 0, 1, 0, 0, 0.5, -1, 1, 0.5, 1, 1};
        double eb[12] = {0, 0, 0, 1, 0, 0, 0.5, -1, -1, 0.5, 1, -1};
        int32_t hit = -1;
        double toi = -1;
        check(tethash_ccd_vertex_face(start, end, 1e-6, 1000000, &hit, &toi) == TETHASH_OK, "ccd_vertex_face");
        check(hit == 1 && toi <= 0.5 && toi > 0.4999, "vertex meets the triangle at t = 0.5");
        check(tethash_ccd_edge_edge(ea, eb, 1e-6, 1000000, &hit, &toi) == TETHASH_OK, "ccd_edge_edge");
        check(hit == 1 && toi <= 0.5 && toi > 0.4999, "edges cross at t = 0.5");
        ea[8] = ea[11] = 4;
        eb[8] = eb[11] = 2;
        check(tethash_ccd_edge_edge(ea, eb, 1e-6, 1000000, &hit, &toi) == TETHASH_OK && hit == 0 && toi == 1,
              "raised edges never meet");
        check(tethash_ccd_vertex_face(start, end, 0, 1000000, &hit, &toi) == TETHASH_ERROR_INVALID_ARGUMENT,
              "tolerance 0 refused");
        check(strstr(tethash_last_error(), "tolerance") != NULL, "message names the tolerance");
        check(tethash_ccd_edge_edge(ea, NULL, 1e-6, 1, &hit, &toi) == TETHASH_ERROR_NULL_ARGUMENT, "NULL refused");
    }
    printf("%s (tethash %s)\n", failures ? "FAILED" : "ok", tethash_version());
    return failures ? 1 : 0;
}
